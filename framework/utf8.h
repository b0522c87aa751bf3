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

// `text` with the control characters a terminal acts on written as escapes,
// for a script's printed line or error message: the C0 bytes but tab and
// newline (NUL as \0, CR as \r, ESC as \x1b, ...), DEL (\x7f) and the C1
// code points U+0080..U+009F in UTF-8 (\u009b). Each newline becomes
// `newline` (a printed line's next lines get the robot's prefix). Other
// bytes, invalid UTF-8 included, are unchanged (ValidUtf8's work).
std::string EscapeControls(std::string_view text, std::string_view newline = "\n");

}  // namespace swarmsim
