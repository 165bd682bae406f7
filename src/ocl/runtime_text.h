// Internal to src/ocl: the few words its messages are made of.
#pragma once
#include <string>
#include <vector>

namespace planarvo::ocl::detail {

inline std::string quote(const std::string& s) { return "\"" + s + "\""; }

inline std::string join(const std::vector<std::string>& items, const std::string& sep) {
  std::string out;
  for (const std::string& i : items) out += (out.empty() ? "" : sep) + i;
  return out;
}

}  // namespace planarvo::ocl::detail
