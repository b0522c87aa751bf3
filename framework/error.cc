#include "framework/error.h"

namespace swarmsim {

void ThrowCheckFailure(const char* condition, const char* file, int line,
                       const std::string& message) {
  throw InternalError(std::string("internal error at ") + file + ":" + std::to_string(line) +
                      ": check '" + condition + "' failed" +
                      (message.empty() ? "" : ": " + message) +
                      " (this is a swarmsim bug; please report it)");
}

}  // namespace swarmsim
