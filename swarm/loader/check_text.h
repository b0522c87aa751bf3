// Tokens and numbers read out of text files by the loader's checks before a
// third-party reader sees them (mesh_check.cc, collada_check.cc,
// urdf_numbers.cc): whitespace-separated tokens, integers and finite
// numbers as the formats write them, and the words of their messages.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace swarmsim::loader {

inline bool IsSpace(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

// Calls f(token) for each whitespace-separated token of `text` until f returns false.
template <typename F>
void ForEachToken(std::string_view text, F&& f) {
  size_t i = 0;
  const size_t n = text.size();
  while (i < n) {
    while (i < n && IsSpace(text[i])) ++i;
    if (i == n) return;
    const size_t begin = i;
    while (i < n && !IsSpace(text[i])) ++i;
    if (!f(text.substr(begin, i - begin))) return;
  }
}

// A non-negative decimal integer of at most `max` (digits only, as an index
// or a count is written).
bool ParseUnsigned(std::string_view t, uint64_t max, uint64_t* value);

// A finite decimal number ("1", "-0.5", "+2.5e-3", ".5"); no "inf", "nan".
bool ParseFinite(std::string_view t, double* value);

// A token for a message: at most 40 characters, printable.
std::string Shown(std::string_view t);
// Shown(t) in single quotes.
std::string Quoted(std::string_view t);
// 2000000 as "2,000,000".
std::string Count(int64_t n);

// Throws swarmsim::Error "name:line: message" (no ":line" when line <= 0).
[[noreturn]] void Fail(const std::string& name, int line, const std::string& message);

// XML the loader's readers (tinyxml2, and urdfdom and assimp behind them)
// would misread, found in a file's bytes before they parse it: a DOCTYPE
// with declarations (its entities and attribute defaults are never
// applied), and a reference to an entity other than XML's own five and
// character references (kept as its literal text). Fails "name:line: ..."
// at the first; `format` names the file's kind ("URDF", "COLLADA").
void CheckXmlHasNoDtd(std::string_view bytes, const std::string& name, const char* format);

// Where an XML file's elements do not nest, found in its bytes for a file
// the parser refused (tinyxml2 names the line of the element it was in,
// not of the tag that broke it): "line N: </robt> does not close <robot>
// (line 2)", "<link> (line 3) is never closed", a closing tag with none
// open (after the root's end), an attribute value missing its closing quote,
// a comment, CDATA section or declaration the file ends in.
// Empty when the tags nest.
// *line: the line to name (0 with an empty answer).
std::string XmlNestingProblem(std::string_view bytes, int* line);

// tinyxml2's error for a file it refused (`error_id` its XMLError,
// `error_str` its ErrorStr(), which may name the element) in words:
// "an attribute of <link> is not name=\"value\" (...)". For what
// XmlNestingProblem does not find.
std::string XmlParseErrorInWords(int error_id, const char* error_str);

// Fails when a mesh file's triangles pass kMaxMeshTriangles (mesh.h).
void CheckTriangleCount(const std::string& name, int line, int64_t triangles, const char* what);

}  // namespace swarmsim::loader
