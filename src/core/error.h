// planarvo's one exception type. Every layer throws planarvo::Error with a code that the C API
// maps to a status one to one, and a message a user can act on (what, and where: file and line).
#pragma once
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
  Internal,         // a bug
};

class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
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
