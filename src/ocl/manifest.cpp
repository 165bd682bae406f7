// Reading and writing the prebuilt-binaries manifest (format in manifest.h).
#include "ocl/manifest.h"

#include <cctype>
#include <cstdlib>

#include "core/error.h"
#include "ocl/program_cache.h"
#include "ocl/runtime.h"

namespace planarvo::ocl::detail {
namespace {

std::string trim_spaces(const std::string& s) {
  size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\r')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\r')) --e;
  return s.substr(b, e - b);
}

std::vector<std::string> split_tabs(const std::string& line) {
  std::vector<std::string> fields;
  size_t start = 0;
  for (;;) {
    const size_t tab = line.find('\t', start);
    fields.push_back(trim_spaces(line.substr(start, tab == std::string::npos ? tab : tab - start)));
    if (tab == std::string::npos) break;
    start = tab + 1;
  }
  return fields;
}

}  // namespace

std::string options_hash(const std::string& normalized_options) {
  return hex64(fnv1a64(normalized_options));
}

std::vector<ManifestEntry> parse_manifest(const std::string& text, const std::string& path) {
  std::vector<ManifestEntry> entries;
  size_t pos = 0;
  int line_no = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    size_t first = 0;
    while (first < line.size() && std::isspace(static_cast<unsigned char>(line[first]))) ++first;
    if (first == line.size() || line[first] == '#') continue;

    const auto where = [&] { return path + ":" + std::to_string(line_no) + ": "; };
    std::vector<std::string> f = split_tabs(line);
    // A hand-written line may end in a TAB that an editor kept.
    if (f.size() >= 6 && f.back().empty()) f.pop_back();
    if (f.size() < 5 || f.size() > 9 || f.size() == 8)
      throw_invalid_input(where() + "expected 5 to 7, or 9, TAB-separated fields (program, options " +
                          "hash, file, device, driver, options, for, size, sha256), found " +
                          std::to_string(f.size()) + " (are the fields separated by TABs?)");
    ManifestEntry e;
    e.program = f[0];
    e.options_hash = f[1];
    e.file = f[2];
    e.device = f[3];
    e.driver = f[4];
    e.options = normalize_build_options(f.size() >= 6 ? f[5] : std::string());
    e.uses = f.size() >= 7 ? f[6] : std::string();
    e.line = line_no;
    if (f.size() == 9) {
      if (f[7] != "-") {
        char* stop = nullptr;
        const long long size = std::strtoll(f[7].c_str(), &stop, 10);
        if (f[7].empty() || *stop != '\0' || size < 0)
          throw_invalid_input(where() + "size \"" + f[7] + "\" is not a number of bytes (or -)");
        e.size = size;
      }
      if (f[8] != "-") {
        const bool hex = f[8].size() == 64 && f[8].find_first_not_of("0123456789abcdef") == std::string::npos;
        if (!hex) throw_invalid_input(where() + "sha256 \"" + f[8] + "\" is not 64 lowercase hex digits (or -)");
        e.sha256 = f[8];
      }
    }
    if (e.program.empty() || e.file.empty() || e.device.empty() || e.driver.empty())
      throw_invalid_input(where() + "program, file, device and driver must not be empty (use * " +
                          "for any device or driver)");
    if (e.options_hash != "-" && e.options_hash != options_hash(e.options))
      throw_invalid_input(where() + "options hash " + e.options_hash +
                          " does not match the options \"" + e.options + "\" (expected " +
                          options_hash(e.options) + "; write - to skip this check)");
    entries.push_back(std::move(e));
  }
  return entries;
}

std::string format_manifest(const std::vector<ManifestEntry>& entries) {
  std::string out =
      "# planarvo kernel binaries manifest, format 3 (see src/ocl/README.md).\n"
      "# One binary per line, TAB-separated: program, options-hash (FNV-1a 64 of the options,\n"
      "# or - to skip the check), file (relative to this directory), device (CL_DEVICE_NAME or\n"
      "# *), driver (CL_DRIVER_VERSION or *), options (normalised build options; may be absent),\n"
      "# for (the commands that need it, comma-separated; may be absent), size (bytes) and\n"
      "# sha256 of the file (both absent, or -, to skip the check).\n";
  for (const ManifestEntry& e : entries) {
    out += e.program + '\t' + e.options_hash + '\t' + e.file + '\t' + e.device + '\t' + e.driver;
    const bool checked = e.size >= 0 || !e.sha256.empty();
    if (!e.options.empty() || !e.uses.empty() || checked) out += '\t' + e.options;
    if (!e.uses.empty() || checked) out += '\t' + e.uses;
    if (checked)
      out += '\t' + (e.size >= 0 ? std::to_string(e.size) : std::string("-")) + '\t' +
             (e.sha256.empty() ? std::string("-") : e.sha256);
    out += '\n';
  }
  return out;
}

}  // namespace planarvo::ocl::detail
