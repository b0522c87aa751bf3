// Text that reaches a file or the console as UTF-8 whatever bytes it came
// from: a world file, a script's print or error, a --set value may carry
// bytes that are not UTF-8, and JSON, CSV and SQLite readers reject them.
#pragma once

#include <string>
#include <string_view>

namespace swarmsim {

// `text` with each invalid UTF-8 sequence (a stray byte, a truncated or
// overlong sequence, a surrogate, a code point past U+10FFFF) replaced by
// U+FFFD, the replacement character, as a JSON writer's "replace" mode and
// WHATWG decoders do: one U+FFFD per maximal invalid subpart. Valid text
// comes back unchanged.
std::string ValidUtf8(std::string_view text);
// Whether ValidUtf8(text) would change nothing.
bool IsValidUtf8(std::string_view text);

}  // namespace swarmsim
