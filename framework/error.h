// Errors.
//
// User mistakes (bad world file, bad script, bad flag) are reported by
// throwing swarmsim::Error with a message a user can act on; the program's
// entry point prints it and exits nonzero. Internal invariants use
// SWARMSIM_CHECK, which stays on in release builds and throws InternalError
// (still caught at the top: a message, never an abort).
#pragma once

#include <stdexcept>
#include <string>

namespace swarmsim {

// A mistake in the user's input: world file, script, command line.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A broken invariant inside swarmsim itself (a bug to report).
class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

[[noreturn]] void ThrowCheckFailure(const char* condition, const char* file, int line,
                                    const std::string& message);

}  // namespace swarmsim

#define SWARMSIM_CHECK(condition, message)                                                      \
  do {                                                                                          \
    if (!(condition)) ::swarmsim::ThrowCheckFailure(#condition, __FILE__, __LINE__, (message)); \
  } while (false)
