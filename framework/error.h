// Errors.
//
// User mistakes (bad world file, bad script, bad flag) are reported by
// throwing swarmsim::Error with a message a user can act on; the program's
// entry point prints it and exits nonzero. Internal invariants use
// SWARMSIM_CHECK, which stays on in release builds and throws InternalError
// (still caught at the top: a message, never an abort).
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace swarmsim {

// The longest error text, in bytes: a script's error('e'):rep(1e7) or an 8 MB
// bad value in a world file must not become megabytes on stderr, in
// summary.json and in each robot's buffers.
inline constexpr size_t kMaxErrorTextBytes = 4096;

// `text` if it has at most `max_bytes` bytes; else its start and its end
// with " ... (N bytes cut) ... " between (at most max_bytes in all), cut
// between UTF-8 characters so that valid UTF-8 stays valid.
std::string CutErrorText(std::string_view text, size_t max_bytes = kMaxErrorTextBytes);

// A mistake in the user's input: world file, script, command line. The
// text is cut to kMaxErrorTextBytes (CutErrorText): the one place every
// error passes, the loader's and the scripts' alike.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(Cut(what)) {}
  explicit Error(const char* what) : Error(std::string(what)) {}

 private:
  static std::string Cut(const std::string& what) {
    return what.size() <= kMaxErrorTextBytes ? what : CutErrorText(what);
  }
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
