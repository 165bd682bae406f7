// The prebuilt-kernel manifest (planarvo-kernels.txt, src/ocl/manifest.h) through its parser, as
// `--kernel-binaries DIR` reads it before any binary reaches a driver. What parses must format
// and parse again to the same entries; what does not is InvalidInput naming the manifest.
#include <string>

#include "core/error.h"
#include "fuzz_common.h"
#include "ocl/manifest.h"

namespace {

bool same(const planarvo::ocl::detail::ManifestEntry& a, const planarvo::ocl::detail::ManifestEntry& b) {
  return a.program == b.program && a.options_hash == b.options_hash && a.file == b.file && a.device == b.device &&
         a.driver == b.driver && a.options == b.options && a.uses == b.uses && a.size == b.size &&
         a.sha256 == b.sha256;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace planarvo::ocl::detail;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string path = "planarvo-kernels.txt";
  std::vector<ManifestEntry> entries;
  try {
    entries = parse_manifest(text, path);
  } catch (const planarvo::Error& e) {
    if (e.code() != planarvo::ErrorCode::InvalidInput) planarvo_fuzz::broken("a bad manifest gave an error other than InvalidInput");
    if (std::string(e.what()).rfind(path, 0) != 0) planarvo_fuzz::broken("a bad manifest's message does not start with its path");
    return 0;
  }
  std::vector<ManifestEntry> again;
  try {
    again = parse_manifest(format_manifest(entries), path);
  } catch (const planarvo::Error& e) {
    std::fprintf(stderr, "planarvo fuzz: %s\n", e.what());
    planarvo_fuzz::broken("a parsed manifest, formatted, does not parse");
  }
  if (again.size() != entries.size()) planarvo_fuzz::broken("a formatted manifest has another number of entries");
  for (size_t i = 0; i < entries.size(); ++i)
    if (!same(entries[i], again[i])) planarvo_fuzz::broken("a formatted manifest reads back different");
  return 0;
}
