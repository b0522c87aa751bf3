#include "swarm/loader/check_text.h"

#include <tinyxml2.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "framework/error.h"
#include "swarm/loader/mesh.h"

namespace swarmsim::loader {

// A non-negative decimal integer of at most `max` (digits only, as an index
// or a count is written).
bool ParseUnsigned(std::string_view t, uint64_t max, uint64_t* value) {
  if (t.empty() || t.size() > 19) return false;
  uint64_t v = 0;
  for (char c : t) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + static_cast<uint64_t>(c - '0');
  }
  if (v > max) return false;
  *value = v;
  return true;
}

// A finite decimal number ("1", "-0.5", "+2.5e-3", ".5").
bool ParseFinite(std::string_view t, double* value) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  if (t.empty() || !(std::isdigit(static_cast<unsigned char>(t.back())) || t.back() == '.'))
    return false;  // no "inf", "nan", "1e"
  double v = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (end != t.data() + t.size()) return false;
  if (ec == std::errc::result_out_of_range) {
    // Too large, or too small: strtod tells (a tiny value reads as about 0).
    const std::string copy(t);
    v = std::strtod(copy.c_str(), nullptr);
  } else if (ec != std::errc()) {
    return false;
  }
  if (!std::isfinite(v)) return false;
  *value = v;
  return true;
}

// A token for a message: at most 40 characters, printable.
std::string Shown(std::string_view t) {
  constexpr size_t kShown = 40;
  std::string out(t.substr(0, kShown));
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
  return t.size() > kShown ? out + "..." : out;
}

std::string Quoted(std::string_view t) {
  std::string out(1, '\'');  // (appended: GCC 12 warns, wrongly, on "'" + std::string)
  out += Shown(t);
  out += '\'';
  return out;
}

std::string Count(int64_t n) {
  std::string digits = std::to_string(n < 0 ? -n : n), out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return (n < 0 ? "-" : "") + out;
}

[[noreturn]] void Fail(const std::string& name, int line, const std::string& message) {
  throw Error(name + (line > 0 ? ":" + std::to_string(line) : "") + ": " + message);
}

void CheckXmlHasNoDtd(std::string_view bytes, const std::string& name, const char* format) {
  int line = 1;
  // Skips to just past `end` from `i`, counting lines; false at the end of the bytes.
  const auto skip_past = [&](size_t* i, std::string_view end) {
    const size_t at = bytes.find(end, *i);
    const size_t stop = at == std::string_view::npos ? bytes.size() : at + end.size();
    for (size_t k = *i; k < stop; ++k) line += bytes[k] == '\n';
    *i = stop;
  };
  for (size_t i = 0; i < bytes.size();) {
    const std::string_view rest = bytes.substr(i);
    if (rest.starts_with("<!--")) {
      skip_past(&i, "-->");
    } else if (rest.starts_with("<![CDATA[")) {
      skip_past(&i, "]]>");
    } else if (rest.starts_with("<?")) {
      skip_past(&i, "?>");
    } else if (rest.starts_with("<!DOCTYPE")) {
      const size_t close = rest.find_first_of(">[");
      if (close != std::string_view::npos && rest[close] == '[')
        Fail(name, line,
             "a <!DOCTYPE> with declarations ([...]): the " + std::string(format) +
                 " reader applies no DTD, so its entities and defaults would be lost; write the "
                 "values out and remove them");
      skip_past(&i, ">");
    } else if (rest[0] == '&') {
      size_t end = 1;
      while (end < rest.size() && end <= 40 &&
             (std::isalnum(static_cast<unsigned char>(rest[end])) || rest[end] == '_' ||
              rest[end] == '-' || rest[end] == '.' || rest[end] == ':' || rest[end] == '#'))
        ++end;
      // A '&' that starts no reference ("l&eft"): XML writes it &amp;, and
      // the two readers behind a URDF disagree on it (tinyxml2 keeps the
      // '&', urdfdom's TinyXML drops it: the joint 'l&eft' was 'left' to
      // one, and the import failed on the name the other gave).
      if (end >= rest.size() || rest[end] != ';' || end == 1)
        Fail(name, line,
             "a '&' that starts no reference (" +
                 Quoted(rest.substr(0, std::min(end + 1, rest.size()))) +
                 "): XML writes a '&' as &amp;");
      const std::string_view entity = rest.substr(1, end - 1);
      if (entity[0] != '#' && entity != "lt" && entity != "gt" && entity != "amp" &&
          entity != "quot" && entity != "apos")
        Fail(name, line,
             Quoted(rest.substr(0, end + 1)) + " refers to an entity the " + format +
                 " reader does not know (it knows XML's own: &lt; &gt; &amp; &quot; &apos; and "
                 "&#...;); write the value out");
      ++i;
    } else {
      line += rest[0] == '\n';
      ++i;
    }
  }
}

namespace {

// "<name> (line 3)".
std::string Element(std::string_view name, int line) {
  std::string out = "<";
  out.append(name);
  out += "> (line ";
  out += std::to_string(line);
  out += ')';
  return out;
}

}  // namespace

std::string XmlParseErrorInWords(int error_id, const char* error_str) {
  // tinyxml2's ErrorStr ends "XMLElement name=link" when it was in an element.
  std::string element;
  if (const std::string_view text = error_str ? error_str : "";
      text.find("XMLElement name=") != std::string_view::npos) {
    const std::string_view rest = text.substr(text.find("XMLElement name=") + 16);
    element = Shown(rest.substr(0, rest.find_first_of(" \t\r\n")));
  }
  const std::string in = element.empty() ? "" : " of <" + element + ">";
  switch (error_id) {
    case tinyxml2::XML_ERROR_PARSING_ELEMENT:
      return "a tag is not well formed (its '>' missing, or a '<' or '&' in text)";
    case tinyxml2::XML_ERROR_PARSING_ATTRIBUTE:
      return "an attribute" + in +
             " is not name=\"value\" (its quotes missing, or an attribute given twice)";
    case tinyxml2::XML_ERROR_PARSING_TEXT: return "text that is not XML (a stray '<' or '&'?)";
    case tinyxml2::XML_ERROR_PARSING_CDATA: return "a <![CDATA[ section is never closed with ]]>";
    case tinyxml2::XML_ERROR_PARSING_COMMENT: return "a comment <!-- is never closed with -->";
    case tinyxml2::XML_ERROR_PARSING_DECLARATION: return "a <? declaration is never closed with ?>";
    case tinyxml2::XML_ERROR_PARSING_UNKNOWN: return "a <! tag is never closed with '>'";
    case tinyxml2::XML_ERROR_EMPTY_DOCUMENT: return "no element: the file is empty or only blanks";
    case tinyxml2::XML_ERROR_MISMATCHED_ELEMENT:
      return "a closing tag does not match the element it closes";
    case tinyxml2::XML_ERROR_PARSING: return "a '<' that starts no element, comment or declaration";
    case tinyxml2::XML_ELEMENT_DEPTH_EXCEEDED: return "elements nested more than 100 deep";
    default:
      return std::string("the XML parser refused it (") + (error_str ? error_str : "no message") +
             ")";
  }
}

std::string XmlNestingProblem(std::string_view bytes, int* line_out) {
  struct Open {
    std::string_view name;
    int line;
  };
  std::vector<Open> open;
  int line = 1;
  *line_out = 0;
  const auto count_lines = [&](size_t from, size_t to) {
    for (size_t k = from; k < to && k < bytes.size(); ++k) line += bytes[k] == '\n';
  };
  const auto is_name_char = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ||
           c == ':' || static_cast<unsigned char>(c) >= 0x80;
  };
  size_t i = 0;
  while (i < bytes.size()) {
    const size_t lt = bytes.find('<', i);
    if (lt == std::string_view::npos) break;
    count_lines(i, lt);
    const std::string_view rest = bytes.substr(lt);
    std::string_view end = ">";
    if (rest.starts_with("<!--"))
      end = "-->";
    else if (rest.starts_with("<![CDATA["))
      end = "]]>";
    else if (rest.starts_with("<?"))
      end = "?>";
    if (end != ">" || rest.starts_with("<!")) {
      const size_t at = bytes.find(end, lt);
      if (at == std::string_view::npos && end != ">") {  // it takes the rest of the file
        *line_out = line;
        const std::string_view what = end == "-->"   ? "a comment <!--"
                                      : end == "]]>" ? "a <![CDATA[ section"
                                                     : "a <? declaration";
        return std::string(what) + " is never closed with " + std::string(end) +
               " (the file ends first)";
      }
      const size_t stop = at == std::string_view::npos ? bytes.size() : at + end.size();
      count_lines(lt, stop);
      i = stop;
      continue;
    }
    const bool closing = rest.size() > 1 && rest[1] == '/';
    size_t k = lt + (closing ? 2 : 1);
    const size_t name_start = k;
    while (k < bytes.size() && is_name_char(bytes[k])) ++k;
    const std::string_view name = bytes.substr(name_start, k - name_start);
    const int tag_line = line;
    // To the tag's end, past quoted attribute values.
    char quote = 0;
    for (; k < bytes.size(); ++k) {
      const char c = bytes[k];
      if (c == '\n') ++line;
      if (quote != 0) {
        if (c == quote) quote = 0;
      } else if (c == '"' || c == '\'') {
        quote = c;
      } else if (c == '>') {
        break;
      }
    }
    if (quote != 0 && !name.empty()) {
      *line_out = tag_line;  // the tag whose value runs away (its quote pairs with a later one)
      std::string message = "an attribute value of <";
      message.append(name);
      message += "> (line " + std::to_string(tag_line) + ") has no closing ";
      return message + (quote == '"' ? "\" (a quote missing?)" : "' (a quote missing?)");
    }
    if (name.empty()) {  // not a tag the parser would take: its own message
      i = k + 1;
      continue;
    }
    const bool self_closing = !closing && k < bytes.size() && k > lt && bytes[k - 1] == '/';
    if (closing) {
      std::string message = "</";
      message.append(name);
      message += "> ";
      if (open.empty()) {
        *line_out = tag_line;
        return message + "closes no open element";
      }
      if (open.back().name != name) {
        *line_out = tag_line;
        const Open& top = open.back();
        const bool opened_below = std::any_of(open.rbegin() + 1, open.rend(),
                                              [&](const Open& o) { return o.name == name; });
        if (opened_below) {
          message += "comes before " + Element(top.name, top.line) + " is closed: it needs its </";
          message.append(top.name);
          return message + "> first (or to end with />)";
        }
        return message + "does not close " + Element(top.name, top.line) + ": is it misspelt?";
      }
      open.pop_back();
    } else if (!self_closing) {
      open.push_back({name, tag_line});
    }
    i = k + 1;
  }
  if (!open.empty()) {
    *line_out = open.back().line;
    return Element(open.back().name, open.back().line) + " is never closed (the file ends first)";
  }
  return "";
}

void CheckTriangleCount(const std::string& name, int line, int64_t triangles, const char* what) {
  if (triangles > kMaxMeshTriangles)
    Fail(name, line,
         std::string(what) + " more than " + Count(kMaxMeshTriangles) +
             " triangles, the limit for a mesh file (simplify it, or split it into parts)");
}

}  // namespace swarmsim::loader
