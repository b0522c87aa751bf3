// Checks on a mesh file's bytes before assimp reads them (mesh.cc). They
// enforce the limits of mesh.h and refuse, naming the file and line, what
// Debian's assimp 5.2 does not survive: a count its assertions abort on, a
// COLLADA index that is not an integer (it loops allocating until memory
// runs out), accessors and headers that make it read out of bounds, node
// instances that recurse without end. tinyxml2 stays in mesh_check.cc.
#pragma once

#include <cstdint>
#include <string>

namespace swarmsim::loader {

// Corners of one polygon face (an OBJ `f` line, a COLLADA <polylist>
// <vcount> value or <polygons> <p>): assimp splits a polygon into triangles
// in time quadratic in its corners (60,000: 10 s), so a larger face is
// refused before assimp sees it. worlds/README.md, Limits.
inline constexpr int64_t kMaxFaceCorners = 1000;

// STL: a binary file's header count against its size (84 + 50 bytes per
// triangle), an ASCII file's facets; both within kMaxMeshTriangles. Throws
// swarmsim::Error "<name>: ...".
void CheckStlBytes(const std::string& bytes, const std::string& name);

// OBJ: every face's indices integers that name vertices the file defines
// (negative ones: relative); positions finite; the triangles (a face of n
// corners makes n - 2) within kMaxMeshTriangles, each face within
// kMaxFaceCorners. Throws swarmsim::Error
// "<name>:<line>: ...".
void CheckObjBytes(const std::string& bytes, const std::string& name);

// COLLADA: well-formed XML of at most kMaxColladaElements elements; each
// data array's count within its values, which are finite numbers; each
// accessor within its array; each primitive element's count, <vcount> and
// <p> agreeing (one <p> for <triangles> and <polylist>, one per primitive
// otherwise), its indices non-negative integers below their source's count,
// a VERTEX input first; node instances without cycles, at most
// kMaxColladaNodeDepth deep and kMaxColladaNodes in all; the triangles, with
// every instance counted, within kMaxMeshTriangles. Returns the document
// assimp is to read: the file's geometry, nodes, materials, effects, images
// and <asset> (its unit), without animations, skins and morphs (an
// <instance_controller> becomes an instance of its skin's geometry), cameras,
// lights and comments. Throws swarmsim::Error "<name>:<line>: ...".
std::string CheckColladaBytes(const std::string& bytes, const std::string& name);

}  // namespace swarmsim::loader
