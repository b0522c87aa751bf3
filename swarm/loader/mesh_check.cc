#include "swarm/loader/mesh_check.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string_view>
#include <vector>

#include "framework/error.h"
#include "swarm/loader/check_text.h"
#include "swarm/loader/mesh.h"

namespace swarmsim::loader {

// --- STL ------------------------------------------------------------------------------

void CheckStlBytes(const std::string& bytes, const std::string& name) {
  // Binary: an 80-byte header, a little-endian triangle count, 50 bytes per
  // triangle (what assimp takes as binary: the count matches the size, in
  // 32-bit arithmetic, which a huge count can wrap around).
  constexpr uint64_t kHeader = 84, kPerTriangle = 50;
  if (bytes.size() >= kHeader) {
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data()) + 80;
    const uint64_t count =
        uint64_t{p[0]} | uint64_t{p[1]} << 8 | uint64_t{p[2]} << 16 | uint64_t{p[3]} << 24;
    const uint64_t needed = kHeader + kPerTriangle * count;
    if (needed == bytes.size()) {
      CheckTriangleCount(name, 0, static_cast<int64_t>(count), "binary STL of");
      return;
    }
    if (static_cast<uint32_t>(needed) == static_cast<uint32_t>(bytes.size()))
      Fail(name, 0,
           "binary STL header says " + Count(static_cast<int64_t>(count)) +
               " triangles, which need " + Count(static_cast<int64_t>(needed)) +
               " bytes, but the file has " + Count(static_cast<int64_t>(bytes.size())));
  }
  // ASCII: "solid", then facets of three vertices each.
  size_t start = 0;
  while (start < bytes.size() && IsSpace(bytes[start])) ++start;
  // What the bytes would be as binary STL: its header's triangle count.
  std::string binary;
  if (bytes.size() >= kHeader) {
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data()) + 80;
    const uint64_t count =
        uint64_t{p[0]} | uint64_t{p[1]} << 8 | uint64_t{p[2]} << 16 | uint64_t{p[3]} << 24;
    binary = "as binary STL its header says " + Count(static_cast<int64_t>(count)) +
             " triangles, which need " +
             Count(static_cast<int64_t>(kHeader + kPerTriangle * count)) + " bytes";
  }
  if (bytes.compare(start, 5, "solid") != 0)
    Fail(name, 0,
         "is neither ASCII STL (starting with 'solid') nor binary STL (84 bytes, then 50 per "
         "triangle): it has " +
             Count(static_cast<int64_t>(bytes.size())) + " bytes" +
             (binary.empty() ? "" : "; " + binary));
  // Line by line: a vertex is three finite numbers (assimp's "Cannot parse
  // string ... as a real number" named no line), and a solid has facets
  // (assimp said "all meshes are orphaned").
  int64_t facets = 0, vertices = 0;
  int line = 1;
  for (size_t at = 0; at < bytes.size(); ++line) {
    const size_t end = std::min(bytes.find('\n', at), bytes.size());
    const std::string_view text(bytes.data() + at, end - at);
    at = end + 1;
    std::vector<std::string_view> words;
    for (size_t i = 0; i < text.size();) {
      while (i < text.size() && IsSpace(text[i])) ++i;
      const size_t from = i;
      while (i < text.size() && !IsSpace(text[i])) ++i;
      if (i > from) words.push_back(text.substr(from, i - from));
    }
    if (words.empty()) continue;
    if (words[0] == "facet") ++facets;
    if (words[0] != "vertex") continue;
    ++vertices;
    double v = 0;
    if (words.size() != 4)
      Fail(name, line,
           "a vertex is 'vertex X Y Z', three numbers (got " + std::to_string(words.size() - 1) +
               ")");
    for (size_t k = 1; k < 4; ++k)
      if (!ParseFinite(words[k], &v))
        Fail(name, line, Quoted(words[k]) + " is not a finite number (in 'vertex X Y Z')");
  }
  // A binary STL's free header may start with "solid" too: one cut short
  // is not binary STL's size, so it is read as ASCII, and has no facets.
  if (facets == 0 && vertices == 0)
    Fail(name, 0,
         "an ASCII STL with no facets: nothing to draw or collide with" +
             (binary.empty()
                  ? std::string()
                  : " (or a binary STL whose header starts with 'solid', cut short: " + binary +
                        ", and the file has " + Count(static_cast<int64_t>(bytes.size())) + ")"));
  CheckTriangleCount(name, 0, std::max(facets, vertices / 3), "ASCII STL of");
}

// --- OBJ ------------------------------------------------------------------------------

void CheckObjBytes(const std::string& bytes, const std::string& name) {
  int64_t positions = 0;  // "v" lines so far
  int64_t triangles = 0, corners = 0;
  int64_t max_index = 0;  // the largest positive position index, and its line
  int max_index_line = 0;
  int line_number = 0;
  std::string joined;  // a line continued with '\' at its end
  size_t at = 0;
  while (at < bytes.size()) {
    ++line_number;
    const int line = line_number;
    size_t end = bytes.find('\n', at);
    if (end == std::string::npos) end = bytes.size();
    std::string_view text(bytes.data() + at, end - at);
    at = end + 1;
    // Continuations: "f 1 2 \" + newline + "3".
    joined.clear();
    while (true) {
      while (!text.empty() && (text.back() == '\r' || IsSpace(text.back()))) text.remove_suffix(1);
      if (text.empty() || text.back() != '\\' || at >= bytes.size()) break;
      joined.append(text.substr(0, text.size() - 1)).push_back(' ');
      ++line_number;
      end = bytes.find('\n', at);
      if (end == std::string::npos) end = bytes.size();
      text = std::string_view(bytes.data() + at, end - at);
      at = end + 1;
    }
    if (!joined.empty()) {
      joined.append(text);
      text = joined;
    }
    size_t i = 0;
    while (i < text.size() && IsSpace(text[i])) ++i;
    size_t k = i;
    while (k < text.size() && !IsSpace(text[k])) ++k;
    const std::string_view keyword = text.substr(i, k - i);
    const std::string_view rest = text.substr(k);
    if (keyword == "v") {
      ++positions;
      int component = 0;
      ForEachToken(rest, [&](std::string_view t) {
        double v;
        if (component++ < 3 && !ParseFinite(t, &v))
          Fail(name, line, "vertex coordinate " + Quoted(t) + " is not a finite number");
        return component < 3;
      });
    } else if (keyword == "f") {
      int64_t n = 0;
      ForEachToken(rest, [&](std::string_view t) {
        // v, v/vt, v//vn or v/vt/vn: each a nonzero integer, negative counting back.
        int part = 0;
        size_t begin = 0;
        while (begin <= t.size()) {
          size_t slash = t.find('/', begin);
          if (slash == std::string_view::npos) slash = t.size();
          const std::string_view number = t.substr(begin, slash - begin);
          if (!(number.empty() && part > 0)) {
            const bool negative = !number.empty() && number[0] == '-';
            uint64_t value = 0;
            if (!ParseUnsigned(number.substr(negative ? 1 : 0), 2147483647, &value) || value == 0)
              Fail(name, line,
                   "face index " + Quoted(t) +
                       " is not a nonzero integer (v, v/vt, v//vn or v/vt/vn; negative counts "
                       "back from the last vertex)");
            if (part == 0 && negative && static_cast<int64_t>(value) > positions)
              Fail(name, line,
                   "face index " + Quoted(t) + " counts back past the first vertex (" +
                       Count(positions) + " so far)");
            if (part == 0 && !negative && static_cast<int64_t>(value) > max_index)
              max_index = static_cast<int64_t>(value), max_index_line = line;
          }
          if (++part > 3)
            Fail(name, line, "face index " + Quoted(t) + " has more than three parts");
          begin = slash + 1;
        }
        ++n;
        return true;
      });
      if (n > kMaxFaceCorners)
        Fail(name, line,
             "a face of " + Count(n) + " corners; at most " + Count(kMaxFaceCorners) +
                 " (split a larger polygon into smaller faces)");
      corners += n;
      if (n >= 3) triangles += n - 2;
      CheckTriangleCount(name, line, triangles, "the faces up to here make");
      if (corners > 3 * kMaxMeshTriangles)
        Fail(name, line,
             "the faces up to here have more than " + Count(3 * kMaxMeshTriangles) +
                 " corners, the limit for a mesh file");
    }
  }
  if (max_index > positions)
    Fail(name, max_index_line,
         "face index " + std::to_string(max_index) + " names a vertex the file does not define (" +
             Count(positions) + " vertices)");
}

}  // namespace swarmsim::loader
