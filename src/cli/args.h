// Command-line parsing for the planarvo tool: "--name value", "--name=value", flags and
// positionals, checked against the options a command declares, so that a typo is an error
// (exit code 2) rather than silently ignored.
#pragma once
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace planarvo::cli {

// Bad usage: main() prints the message and the command's usage, and exits with 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct OptionSpec {
  std::string name;      // without the leading "--"
  std::string value;     // placeholder for the value ("DIR"); empty for a flag
  std::string help;
  std::string fallback;  // default shown in the help, "" for none
};

class Args {
 public:
  Args(const std::vector<OptionSpec>& specs, int argc, char** argv, int first);

  bool has(const std::string& name) const { return values_.count(name) > 0; }
  std::string get(const std::string& name, const std::string& fallback = "") const;
  double get_double(const std::string& name, double fallback) const;
  long long get_int(const std::string& name, long long fallback) const;
  // An integer option that, when given, must lie in [lo, hi]: UsageError naming the option
  // otherwise; fallback when not given.
  int get_int_in(const std::string& name, int fallback, int lo, int hi) const;
  // Exactly `count` positional arguments (what: their names, e.g. "DATASET"): UsageError saying
  // which is missing or which one is unexpected.
  void expect_positionals(size_t count, const std::string& what) const;
  // The file options that name outputs (e.g. "output", "stats"): each one given must be in a
  // directory that exists, checked before any work (the tool's one rule: it never creates
  // directories for output files; `simulate --out` and `kernels --export` name directories and
  // create them). UsageError naming the option as typed otherwise.
  void expect_output_files(const std::vector<std::string>& names) const;
  // Comma-separated numbers, exactly `count` of them.
  std::vector<double> get_doubles(const std::string& name, size_t count) const;
  // "T:a,b,..." (a time, then exactly `count` comma-separated numbers): *time gets T.
  std::vector<double> get_stamped_doubles(const std::string& name, size_t count, double* time) const;
  const std::vector<std::string>& positionals() const { return positionals_; }

 private:
  const OptionSpec* find(const std::string& name) const;
  std::vector<OptionSpec> specs_;
  std::map<std::string, std::string> values_;
  std::vector<std::string> positionals_;
};

std::string format_options(const std::vector<OptionSpec>& specs);

}  // namespace planarvo::cli
