// planarvo's one exception type. Every layer throws planarvo::Error with a code that the C API
// maps to a status one to one, and a message a user can act on (what, and where: file and line).
#pragma once
#include <cstddef>
#include <stdexcept>
#include <string>

namespace planarvo {

enum class ErrorCode {
  InvalidArgument,  // a caller passed a bad value (API misuse)
  InvalidInput,     // a file or data set is missing, unreadable or malformed
  Io,               // a file could not be written
  NoDevice,         // no usable OpenCL device
  OpenCL,           // an OpenCL call or a program build failed
  Failed,           // the work ran but failed: tracking lost, no convergence, unobservable
  Cancelled,        // a progress callback asked to stop
  OutOfMemory,      // an allocation failed (host memory, or a device's for its buffers)
  Internal,         // a bug
};

// The message as a C string can carry it (what() is one): a byte that would cut it (NUL) or
// garble a terminal (other control characters but newline and tab) is written \xNN, and a message
// longer than kMaxErrorMessage bytes (a file's whole line, a path of megabytes) keeps its start
// and its end. Applying it twice changes nothing more.
inline constexpr size_t kMaxErrorMessage = 4096;
std::string printable_message(const std::string& message);

class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& message) : std::runtime_error(printable_message(message)), code_(code) {}
  ErrorCode code() const noexcept { return code_; }

 private:
  ErrorCode code_;
};

// Shorthands for the common throws.
[[noreturn]] inline void throw_invalid_input(const std::string& message) {
  throw Error(ErrorCode::InvalidInput, message);
}
[[noreturn]] inline void throw_invalid_argument(const std::string& message) {
  throw Error(ErrorCode::InvalidArgument, message);
}

}  // namespace planarvo
