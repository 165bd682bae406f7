// STUB: replaced by the MCAP reader.
#include "core/error.h"
#include "io/bag/bag.h"

namespace planarvo::io::bag {
std::unique_ptr<BagFile> open_mcap(const std::string& path) { throw_invalid_input(path + ": not implemented"); }
}  // namespace planarvo::io::bag
