// The OctoMap file formats, checked before the library reads them: the
// library's readers (OcTree::readBinary, AbstractOcTree::read) trust their
// input: a truncated body makes them read indeterminate bytes and recurse
// without a depth limit, which may allocate without bound or crash. So
// every file is parsed here first, header and body, without building a
// tree, and only a well-formed one is handed to the library.
//
// The two formats (octomap 1.9, AbstractOcTree.cpp, OcTreeBaseImpl.hxx,
// OccupancyOcTreeBase.hxx):
//   header   text lines: a first line that starts with kBinaryFirstLine
//            (.bt) or kFullFirstLine (.ot), then whitespace-separated
//            tokens: `# ...` comments to the end of the line, `id NAME`,
//            `size N` (nodes in the tree), `res R` (m), and `data`, after
//            whose line the body starts.
//   .bt body depth-first from the root, 2 bytes per inner node: child i's
//            2-bit code at bit 2i (0 unknown, 1 free leaf, 2 occupied leaf,
//            3 inner node, whose own 2 bytes follow later).
//   .ot body depth-first from the root, per node its value (a 4-byte float
//            log-odds for an OcTree) and a byte whose bit i says child i
//            exists.
// No OctoMap types here: testable on bytes alone.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace swarmsim::environment {

inline constexpr std::string_view kBinaryFirstLine = "# Octomap OcTree binary file";
inline constexpr std::string_view kFullFirstLine = "# Octomap OcTree file";
inline constexpr int kTreeDepth = 16;  // octomap's OcTree: leaves at depth 16

enum class OctomapFormat { kBinary, kFull };  // .bt, .ot

struct OctomapHeader {
  OctomapFormat format = OctomapFormat::kBinary;
  std::string id;          // tree type: "OcTree", "ColorOcTree", ...
  uint64_t size = 0;       // nodes in the tree, as the header says
  double resolution = 0;   // m
  size_t body_offset = 0;  // bytes from the start of the file to the body
};

// Reads the header at the start of `bytes` (the whole header must be
// there). Throws swarmsim::Error, with a message that does not name the
// file, if the first line is not an OctoMap one, a key is malformed, or
// `id`, `res` or `data` is missing.
OctomapHeader ParseOctomapHeader(std::string_view bytes);

struct OctomapBodyCounts {
  uint64_t nodes = 0;            // all nodes, the root included
  uint64_t leaves = 0;           // nodes without children
  uint64_t occupied_leaves = 0;  // .bt only: leaves coded occupied
  size_t bytes = 0;              // length of the body the tree takes
};

// Walks a body without building the tree. Throws swarmsim::Error (no file
// name in the message) if it ends before the tree does ("truncated"), if
// the tree has more nodes than `expected_nodes` (the header's size), or an
// inner node below the deepest level. Bytes after the tree are not read
// (counts.bytes < body.size()). An empty tree (expected_nodes 0) reads no
// bytes.
OctomapBodyCounts CheckBinaryBody(std::span<const uint8_t> body, uint64_t expected_nodes);
// The same for a .ot body of an OcTree (node values of `value_bytes`).
OctomapBodyCounts CheckFullBody(std::span<const uint8_t> body, uint64_t expected_nodes,
                                size_t value_bytes = 4);

}  // namespace swarmsim::environment
