#include "core/error.h"

#include <algorithm>

namespace planarvo {

std::string printable_message(const std::string& message) {
  std::string out;
  out.reserve(std::min(message.size(), kMaxErrorMessage) + 16);
  for (const char c : message) {
    const auto u = static_cast<unsigned char>(c);
    if ((u < 0x20 && c != '\n' && c != '\t') || u == 0x7f) {
      static const char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 15];
    } else {
      out += c;
    }
  }
  if (out.size() > kMaxErrorMessage) {
    // Cut between characters, not inside a UTF-8 sequence.
    const auto continuation = [&](size_t i) { return (static_cast<unsigned char>(out[i]) & 0xc0) == 0x80; };
    size_t head = kMaxErrorMessage * 3 / 4, tail = kMaxErrorMessage / 8;
    while (head > 0 && continuation(head)) --head;
    while (tail < out.size() && continuation(out.size() - tail)) ++tail;
    out = out.substr(0, head) + " [... " + std::to_string(out.size() - head - tail) + " bytes left out ...] " +
          out.substr(out.size() - tail);
  }
  return out;
}

}  // namespace planarvo
