#include "modules/environment/octomap_format.h"

#include <charconv>
#include <cmath>
#include <cstring>
#include <string>

#include "framework/error.h"

namespace swarmsim::environment {
namespace {

// The first line, for messages: printable ASCII only, at most 60 characters.
std::string Quote(std::string_view line) {
  std::string out = "\"";
  for (size_t i = 0; i < line.size() && i < 60; ++i) {
    const unsigned char c = static_cast<unsigned char>(line[i]);
    out += c >= 0x20 && c < 0x7f ? static_cast<char>(c) : '?';
  }
  if (line.size() > 60) out += "...";
  return out + "\"";
}

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v'; }

// octomap's header reader: `s >> token`, and skipping to the end of a line.
class HeaderTokens {
 public:
  HeaderTokens(std::string_view bytes, size_t at) : bytes_(bytes), at_(at) {}
  bool Next(std::string_view* token) {
    while (at_ < bytes_.size() && IsSpace(bytes_[at_])) ++at_;
    const size_t start = at_;
    while (at_ < bytes_.size() && !IsSpace(bytes_[at_])) ++at_;
    *token = bytes_.substr(start, at_ - start);
    return !token->empty();
  }
  void SkipLine() {
    while (at_ < bytes_.size() && bytes_[at_] != '\n') ++at_;
    if (at_ < bytes_.size()) ++at_;
  }
  size_t at() const { return at_; }

 private:
  std::string_view bytes_;
  size_t at_;
};

[[noreturn]] void Fail(const std::string& message) { throw Error(message); }

// The node count of a tree that promises `expected` nodes and has read `nodes`.
void CountNode(uint64_t* nodes, uint64_t expected) {
  if (++*nodes > expected)
    Fail("the tree has more nodes than the header's 'size " + std::to_string(expected) +
         "' (a corrupt file, or a wrong size)");
}

[[noreturn]] void Truncated(uint64_t nodes, uint64_t expected, size_t body_bytes) {
  Fail("truncated: the data ends (after " + std::to_string(body_bytes) + " bytes, " +
       std::to_string(nodes) + " nodes) before the tree does (the header says 'size " +
       std::to_string(expected) + "' nodes)");
}

struct BinaryWalk {
  std::span<const uint8_t> body;
  uint64_t expected;
  size_t at = 0;
  OctomapBodyCounts counts;

  // Reads the record of an inner node at `depth` (its children are at depth + 1).
  void Node(int depth) {
    if (body.size() - at < 2) Truncated(counts.nodes, expected, body.size());
    const unsigned bits = unsigned(body[at]) | unsigned(body[at + 1]) << 8;
    at += 2;
    for (int i = 0; i < 8; ++i) {
      const unsigned code = (bits >> (2 * i)) & 3;
      if (code == 0) continue;
      CountNode(&counts.nodes, expected);
      if (code == 3 && depth + 1 >= kTreeDepth)
        Fail("corrupt: an inner node at depth " + std::to_string(depth + 1) +
             ", where an OcTree has only leaves (byte " + std::to_string(at - 2) + " of the data)");
      if (code != 3) ++counts.leaves;
      if (code == 2) ++counts.occupied_leaves;
    }
    for (int i = 0; i < 8; ++i)
      if (((bits >> (2 * i)) & 3) == 3) Node(depth + 1);
  }
};

struct FullWalk {
  std::span<const uint8_t> body;
  uint64_t expected;
  size_t value_bytes;
  size_t at = 0;
  OctomapBodyCounts counts;

  // Reads the node at `depth` and, depth first, its children.
  void Node(int depth) {
    if (body.size() - at < value_bytes + 1) Truncated(counts.nodes, expected, body.size());
    CountNode(&counts.nodes, expected);
    at += value_bytes;
    const unsigned children = body[at++];
    if (children == 0) {
      ++counts.leaves;
      return;
    }
    if (depth >= kTreeDepth)
      Fail("corrupt: a node at depth " + std::to_string(depth) +
           " has children, where an OcTree has only leaves (byte " + std::to_string(at - 1) +
           " of the data)");
    for (int i = 0; i < 8; ++i)
      if ((children >> i) & 1) Node(depth + 1);
  }
};

}  // namespace

OctomapHeader ParseOctomapHeader(std::string_view bytes) {
  OctomapHeader header;
  const size_t eol = bytes.find('\n');
  const std::string_view first = bytes.substr(0, eol);
  if (first.starts_with(kBinaryFirstLine)) {
    header.format = OctomapFormat::kBinary;
  } else if (first.starts_with(kFullFirstLine)) {
    header.format = OctomapFormat::kFull;
  } else {
    Fail("not an OctoMap file: its first line is " + Quote(first) + ", expected \"" +
         std::string(kBinaryFirstLine) + "\" (.bt) or \"" + std::string(kFullFirstLine) +
         "\" (.ot); an old header-less .bt converts with octomap's convert_octree");
  }
  if (eol == std::string_view::npos) Fail("the header ends after its first line (no 'data' line)");
  HeaderTokens tokens(bytes, eol + 1);
  bool has_size = false, has_res = false;
  std::string_view token;
  for (;;) {
    if (!tokens.Next(&token)) Fail("the header has no 'data' line (a truncated or broken file)");
    if (token == "data") {
      tokens.SkipLine();
      break;
    }
    if (token.starts_with("#")) {
      tokens.SkipLine();
    } else if (token == "id" || token == "size" || token == "res") {
      std::string_view value;
      if (!tokens.Next(&value)) Fail("the header's '" + std::string(token) + "' has no value");
      const char* end = value.data() + value.size();
      if (token == "id") {
        header.id = std::string(value);
      } else if (token == "size") {
        uint64_t size = 0;
        const auto [ptr, ec] = std::from_chars(value.data(), end, size);
        if (ec != std::errc() || ptr != end || size > 0xffffffffu)
          Fail("the header's 'size " + std::string(value) +
               "' is not a node count (a whole number below 2^32)");
        header.size = size;
        has_size = true;
      } else {
        double res = 0;
        const auto [ptr, ec] = std::from_chars(value.data(), end, res);
        if (ec != std::errc() || ptr != end || !(res > 0) || !std::isfinite(res))
          Fail("the header's 'res " + std::string(value) +
               "' is not a positive resolution in metres");
        // The tree spans 2^16 cells a side, centred on the origin: past
        // 30.5 m a cell, it reaches beyond the 1e6 m a world may use (a
        // 1e30 m cell swallowed every robot in one voxel, with no word).
        if (res * 32768 > 1e6)
          Fail("the header's 'res " + std::string(value) +
               "' is more than 30.5 m: the tree's 65,536 cells a side would reach past the 1e6 "
               "m a world may use");
        header.resolution = res;
        has_res = true;
      }
    } else {
      tokens.SkipLine();  // octomap skips unknown keywords too
    }
  }
  if (header.id.empty()) Fail("the header has no 'id' (the tree type, e.g. 'id OcTree')");
  if (header.id == "1") header.id = "OcTree";  // octomap's deprecated id
  if (!has_res) Fail("the header has no 'res' (the resolution in metres)");
  if (!has_size) Fail("the header has no 'size' (the number of nodes)");
  header.body_offset = tokens.at();
  return header;
}

OctomapBodyCounts CheckBinaryBody(std::span<const uint8_t> body, uint64_t expected_nodes) {
  BinaryWalk walk{body, expected_nodes, 0, {}};
  if (expected_nodes == 0) return walk.counts;    // the library reads no data then
  CountNode(&walk.counts.nodes, expected_nodes);  // the root
  walk.Node(0);
  if (walk.counts.nodes != expected_nodes)
    Fail("the tree has " + std::to_string(walk.counts.nodes) + " nodes, the header's 'size' " +
         std::to_string(expected_nodes) + " (a corrupt file, or a wrong size)");
  walk.counts.bytes = walk.at;
  return walk.counts;
}

OctomapBodyCounts CheckFullBody(std::span<const uint8_t> body, uint64_t expected_nodes,
                                size_t value_bytes) {
  FullWalk walk{body, expected_nodes, value_bytes, 0, {}};
  if (expected_nodes == 0) return walk.counts;
  walk.Node(0);
  if (walk.counts.nodes != expected_nodes)
    Fail("the tree has " + std::to_string(walk.counts.nodes) + " nodes, the header's 'size' " +
         std::to_string(expected_nodes) + " (a corrupt file, or a wrong size)");
  walk.counts.bytes = walk.at;
  return walk.counts;
}

}  // namespace swarmsim::environment
