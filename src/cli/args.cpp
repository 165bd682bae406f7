#include "args.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

namespace planarvo::cli {

Args::Args(const std::vector<OptionSpec>& specs, int argc, char** argv, int first) : specs_(specs) {
  for (int i = first; i < argc; ++i) {
    std::string a = argv[i];
    if (a.size() > 2 && a.compare(0, 2, "--") == 0) {
      std::string name = a.substr(2), value;
      const size_t eq = name.find('=');
      const bool inline_value = eq != std::string::npos;
      if (inline_value) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
      }
      const OptionSpec* spec = find(name);
      if (!spec) throw UsageError("unknown option --" + name);
      if (spec->value.empty()) {
        if (inline_value) throw UsageError("option --" + name + " takes no value");
        value = "1";
      } else if (!inline_value) {
        if (i + 1 >= argc) throw UsageError("option --" + name + " needs a value (" + spec->value + ")");
        value = argv[++i];
      }
      values_[name] = value;
    } else if (a == "-o") {
      if (!find("output")) throw UsageError("unknown option -o");
      if (i + 1 >= argc) throw UsageError("option -o needs a value");
      values_["output"] = argv[++i];
    } else if (a.size() > 1 && a[0] == '-' && !(std::isdigit(static_cast<unsigned char>(a[1])) || a[1] == '.')) {
      throw UsageError("unknown option " + a);
    } else {
      positionals_.push_back(a);
    }
  }
}

const OptionSpec* Args::find(const std::string& name) const {
  for (const auto& s : specs_)
    if (s.name == name) return &s;
  return nullptr;
}

std::string Args::get(const std::string& name, const std::string& fallback) const {
  auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

namespace {
double parse_double(const std::string& name, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
    throw UsageError("option --" + name + ": \"" + text + "\" is not a finite number");
  return v;
}
}  // namespace

double Args::get_double(const std::string& name, double fallback) const {
  return has(name) ? parse_double(name, get(name)) : fallback;
}

long long Args::get_int(const std::string& name, long long fallback) const {
  if (!has(name)) return fallback;
  const std::string text = get(name);
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE)
    throw UsageError("option --" + name + ": \"" + text + "\" is not an integer");
  return v;
}

int Args::get_int_in(const std::string& name, int fallback, int lo, int hi) const {
  if (!has(name)) return fallback;
  const long long v = get_int(name, fallback);
  if (v < lo || v > hi)
    throw UsageError("option --" + name + " must be " + std::to_string(lo) + " to " + std::to_string(hi) + ", not " +
                     get(name));
  return static_cast<int>(v);
}

void Args::expect_positionals(size_t count, const std::string& what) const {
  if (positionals_.size() < count) throw UsageError("missing " + what);
  if (positionals_.size() > count) throw UsageError("unexpected argument " + positionals_[count]);
}

void Args::expect_output_files(const std::vector<std::string>& names) const {
  for (const std::string& name : names) {
    if (!has(name)) continue;
    const std::string path = get(name);
    const std::string flag = name == "output" ? "-o" : "--" + name;
    if (path.empty()) throw UsageError("option " + flag + " needs a file name");
    const std::filesystem::path dir = std::filesystem::path(path).parent_path();
    std::error_code ec;
    if (std::filesystem::is_directory(std::filesystem::path(path), ec))
      throw UsageError("option " + flag + ": " + path + " is a directory, not a file");
    if (!dir.empty() && !std::filesystem::is_directory(dir, ec))
      throw UsageError("option " + flag + ": the directory " + dir.string() + " does not exist (create it first)");
  }
}

std::vector<double> Args::get_doubles(const std::string& name, size_t count) const {
  std::vector<double> out;
  std::stringstream ss(get(name));
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(parse_double(name, item));
  if (out.size() != count)
    throw UsageError("option --" + name + " needs " + std::to_string(count) +
                     " comma-separated numbers, got \"" + get(name) + "\"");
  return out;
}

std::vector<double> Args::get_stamped_doubles(const std::string& name, size_t count, double* time) const {
  const std::string text = get(name);
  const size_t colon = text.find(':');
  if (colon == std::string::npos)
    throw UsageError("option --" + name + " needs T:" + std::string(count > 0 ? "a" : "") +
                     (count > 1 ? ",b" : "") + (count > 2 ? ",..." : "") + " (a time, a colon, then " +
                     std::to_string(count) + " comma-separated numbers), got \"" + text + "\"");
  *time = parse_double(name, text.substr(0, colon));
  std::vector<double> out;
  std::stringstream ss(text.substr(colon + 1));
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(parse_double(name, item));
  if (out.size() != count)
    throw UsageError("option --" + name + " needs " + std::to_string(count) + " comma-separated numbers after the colon, got \"" +
                     text + "\"");
  return out;
}

std::string format_options(const std::vector<OptionSpec>& specs) {
  std::ostringstream os;
  for (const auto& s : specs) {
    std::string left = "  --" + s.name + (s.value.empty() ? "" : " " + s.value);
    if (left.size() < 34) left.resize(34, ' ');
    else left += "\n" + std::string(34, ' ');
    os << left << s.help;
    if (!s.fallback.empty()) os << " (default: " << s.fallback << ")";
    os << "\n";
  }
  return os.str();
}

}  // namespace planarvo::cli
