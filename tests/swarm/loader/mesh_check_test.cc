// The checks on an STL or OBJ file before assimp reads it
// (swarm/loader/mesh_check.cc; COLLADA's: collada_check_test.cc): each rule
// refuses its case with the file, the line and what is wrong.
#include "swarm/loader/mesh_check.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "framework/error.h"

namespace swarmsim::loader {
namespace {

namespace fs = std::filesystem;

const fs::path kMeshes = fs::path(SWARMSIM_SOURCE_DIR) / "tests/data/meshes";

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string StlError(const std::string& bytes) {
  try {
    CheckStlBytes(bytes, "part.stl");
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

std::string Binary(uint32_t count, size_t size) {
  std::string bytes(80, ' ');
  for (int k = 0; k < 4; ++k) bytes += static_cast<char>((count >> (8 * k)) & 0xff);
  bytes.resize(size, '\0');
  return bytes;
}

TEST(MeshCheckTest, StlHeaderCountMatchesTheFile) {
  EXPECT_EQ(StlError(Binary(2, 184)), "no error");
  EXPECT_EQ(StlError(Binary(0x80000000u, 84)),
            "part.stl: binary STL header says 2,147,483,648 triangles, which need "
            "107,374,182,484 bytes, but the file has 84");
  EXPECT_EQ(StlError(Binary(3, 184)),
            "part.stl: is neither ASCII STL (starting with 'solid') nor binary STL (84 bytes, then "
            "50 per triangle): it has 184 bytes; as binary STL its header says 3 triangles, which "
            "need 234 bytes");
  EXPECT_EQ(StlError(Binary(2000001, 84 + 50 * size_t{2000001})),
            "part.stl: binary STL of more than 2,000,000 triangles, the limit for a mesh file "
            "(simplify it, or split it into parts)");
  EXPECT_EQ(StlError(ReadAll(kMeshes / "unit_cube.stl")), "no error");
}

// ASCII STL: a vertex that is no three numbers is named at its line, and a
// solid without facets is said to be empty (assimp's messages had neither).
TEST(MeshCheckTest, AsciiStlVerticesAreNumbersAtTheirLines) {
  const std::string facet =
      "  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n"
      "      vertex 0 1 0\n    endloop\n  endfacet\n";
  EXPECT_EQ(StlError("solid t\n" + facet + "endsolid t\n"), "no error");
  std::string bad = "solid t\n" + facet + "endsolid t\n";
  bad.replace(bad.find("vertex 1 0 0"), 12, "vertex 1 abc 0");
  EXPECT_EQ(StlError(bad), "part.stl:5: 'abc' is not a finite number (in 'vertex X Y Z')");
  bad = "solid t\n" + facet + "endsolid t\n";
  bad.replace(bad.find("vertex 0 1 0"), 12, "vertex 0 1");
  EXPECT_EQ(StlError(bad), "part.stl:6: a vertex is 'vertex X Y Z', three numbers (got 2)");
  EXPECT_EQ(StlError("solid empty\nendsolid empty\n"),
            "part.stl: an ASCII STL with no facets: nothing to draw or collide with");
  // A binary STL's header may start with "solid" (a published robot's
  // foot): cut short, it is no binary STL's size and reads as ASCII, which
  // the message says it may not be.
  std::string cut = "solid foot" + std::string(70, ' ') + std::string("\x03\0\0\0", 4);
  cut += std::string(16, '\0');
  EXPECT_EQ(StlError(cut),
            "part.stl: an ASCII STL with no facets: nothing to draw or collide with (or a binary "
            "STL whose header starts with 'solid', cut short: as binary STL its header says 3 "
            "triangles, which need 234 bytes, and the file has 100)");
}

std::string ObjError(const std::string& text) {
  try {
    CheckObjBytes(text, "part.obj");
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(MeshCheckTest, ObjFacesNameVerticesTheFileDefines) {
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  EXPECT_EQ(ObjError(v + "f 1 2 3\nf 1/1 2/2 3/3\nf 1//1 2//1 3//1\nf -3 -2 -1\n"), "no error");
  EXPECT_EQ(ObjError(v + "f 1 2 \\\n 3\n"), "no error");  // a continued line
  EXPECT_EQ(ObjError(v + "f 1 2 4\n"),
            "part.obj:4: face index 4 names a vertex the file does not define (3 vertices)");
  EXPECT_EQ(ObjError(v + "f 1 2 -4\n"),
            "part.obj:4: face index '-4' counts back past the first vertex (3 so far)");
  EXPECT_EQ(ObjError(v + "f 1 2 3.5\n"),
            "part.obj:4: face index '3.5' is not a nonzero integer (v, v/vt, v//vn or v/vt/vn; "
            "negative counts back from the last vertex)");
  EXPECT_EQ(ObjError(v + "f 0 1 2\n").substr(0, 36), "part.obj:4: face index '0' is not a ");
  EXPECT_EQ(ObjError("v 0 0 0\nv 1 inf 0\n"),
            "part.obj:2: vertex coordinate 'inf' is not a finite number");
}

// A polygon's split into triangles takes assimp time quadratic in its
// corners (60,000: 10 s): a face past kMaxFaceCorners is refused first.
TEST(MeshCheckTest, ObjFacesHaveAtMostAThousandCorners) {
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const auto face = [](int corners) {
    std::string f = "f";
    for (int k = 0; k < corners; ++k) {
      f += ' ';
      f += static_cast<char>('1' + k % 3);
    }
    f += '\n';
    return f;
  };
  EXPECT_EQ(ObjError(v + face(1000)), "no error");
  EXPECT_EQ(ObjError(v + "f 1 2 3\n" + face(1001)),
            "part.obj:5: a face of 1,001 corners; at most 1,000 (split a larger polygon into "
            "smaller faces)");
  EXPECT_EQ(ObjError(v + face(60000)).substr(0, 38), "part.obj:4: a face of 60,000 corners; ");
}

}  // namespace
}  // namespace swarmsim::loader
