// The benchmarks' command lines: key=value arguments.
#pragma once
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace planarvo::bench {

using Args = std::map<std::string, std::string>;

// argv[1..] as key=value pairs; anything else is a usage error (exit 2) naming the program.
inline Args parse_args(int argc, char** argv, const char* program) {
  Args m;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto eq = a.find('=');
    if (eq == std::string::npos) {
      std::fprintf(stderr, "%s: arguments are key=value, not %s\n", program, a.c_str());
      std::exit(2);
    }
    m[a.substr(0, eq)] = a.substr(eq + 1);
  }
  return m;
}

inline std::string get(const Args& m, const std::string& key, const std::string& fallback) {
  const auto it = m.find(key);
  return it == m.end() ? fallback : it->second;
}

inline std::vector<std::string> split(const std::string& s, char separator = ',') {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, separator)) out.push_back(item);
  return out;
}

}  // namespace planarvo::bench
