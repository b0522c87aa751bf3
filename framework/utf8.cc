#include "framework/utf8.h"

#include <cstdint>

namespace swarmsim {
namespace {

constexpr std::string_view kReplacement = "\xEF\xBF\xBD";  // U+FFFD

// The length of the valid sequence starting at text[i], or 0 if invalid
// there; `*consumed` is how many bytes the invalid start covers (the maximal
// subpart: a lead byte and the continuation bytes that still fit it).
size_t ValidSequence(std::string_view text, size_t i, size_t* consumed) {
  const auto byte = [&](size_t k) { return static_cast<uint8_t>(text[k]); };
  const uint8_t lead = byte(i);
  *consumed = 1;
  if (lead < 0x80) return 1;
  size_t length;
  uint8_t low = 0x80, high = 0xBF;  // the allowed range of the second byte
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    if (lead == 0xE0) low = 0xA0;   // overlong
    if (lead == 0xED) high = 0x9F;  // surrogates
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    if (lead == 0xF0) low = 0x90;   // overlong
    if (lead == 0xF4) high = 0x8F;  // past U+10FFFF
  } else {
    return 0;
  }
  for (size_t k = 1; k < length; ++k) {
    if (i + k >= text.size()) return 0;
    const uint8_t b = byte(i + k);
    if (k == 1 ? (b < low || b > high) : (b < 0x80 || b > 0xBF)) return 0;
    *consumed = k + 1;
  }
  return length;
}

// How many bytes from the start of `text` are valid UTF-8.
size_t ValidPrefix(std::string_view text) {
  size_t i = 0;
  while (i < text.size()) {
    size_t consumed;
    const size_t length = ValidSequence(text, i, &consumed);
    if (length == 0) break;
    i += length;
  }
  return i;
}

}  // namespace

bool IsValidUtf8(std::string_view text) { return ValidPrefix(text) == text.size(); }

std::string ValidUtf8(std::string_view text) {
  size_t i = ValidPrefix(text);
  if (i == text.size()) return std::string(text);
  std::string out;
  out.reserve(text.size() + 8);
  out.append(text.substr(0, i));
  while (i < text.size()) {
    size_t consumed;
    const size_t length = ValidSequence(text, i, &consumed);
    if (length > 0) {
      out.append(text.substr(i, length));
      i += length;
    } else {
      out.append(kReplacement);
      i += consumed;
    }
  }
  return out;
}

std::string EscapeControls(std::string_view text, std::string_view newline) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<uint8_t>(text[i]);
    if (c == '\n') {
      out += newline;
    } else if (c == '\t' || (c >= 0x20 && c != 0x7f && c != 0xc2)) {
      out += static_cast<char>(c);
    } else if (c == 0xc2) {  // U+0080..U+00BF: C1 controls up to U+009F
      const auto next = i + 1 < text.size() ? static_cast<uint8_t>(text[i + 1]) : 0;
      if (next >= 0x80 && next <= 0x9f) {
        out += "\\u00";
        out += kHex[next >> 4];
        out += kHex[next & 15];
        ++i;
      } else {
        out += static_cast<char>(c);
      }
    } else if (c == 0) {
      out += "\\0";
    } else if (c == '\r') {
      out += "\\r";
    } else {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  return out;
}

}  // namespace swarmsim
