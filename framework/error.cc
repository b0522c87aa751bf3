#include "framework/error.h"

#include "framework/start_thread.h"

namespace swarmsim {

namespace {
bool IsContinuationByte(char c) { return (static_cast<unsigned char>(c) & 0xC0) == 0x80; }
}  // namespace

std::string CutErrorText(std::string_view text, size_t max_bytes) {
  if (text.size() <= max_bytes) return std::string(text);
  // The note's longest form (the count has at most as many digits as the size).
  const std::string widest = " ... (" + std::to_string(text.size()) + " bytes cut) ... ";
  if (max_bytes < widest.size() + 8) max_bytes = widest.size() + 8;
  const size_t room = max_bytes - widest.size();
  // Three quarters from the start (where the file:line is), the rest from
  // the end (where a script error names its callback and object).
  size_t head = room - room / 4;
  size_t tail_start = text.size() - room / 4;
  while (head > 0 && IsContinuationByte(text[head])) --head;
  while (tail_start < text.size() && IsContinuationByte(text[tail_start])) ++tail_start;
  std::string out(text.substr(0, head));
  out += " ... (" + std::to_string(tail_start - head) + " bytes cut) ... ";
  out += text.substr(tail_start);
  return out;
}

void ThrowCheckFailure(const char* condition, const char* file, int line,
                       const std::string& message) {
  throw InternalError(std::string("internal error at ") + file + ":" + std::to_string(line) +
                      ": check '" + condition + "' failed" +
                      (message.empty() ? "" : ": " + message) +
                      " (this is a swarmsim bug; please report it)");
}

std::string CannotStartThreadMessage(const char* what, const std::system_error& error) {
  return std::string("cannot start a thread for ") + what + ": " + error.what() +
         " (the system gave this process no more threads, or no room for a thread's stack: "
         "see `ulimit -u`, the threads a user may run, and `ulimit -v`, the address space, "
         "against `ulimit -s`, which each thread's stack takes)";
}

}  // namespace swarmsim
