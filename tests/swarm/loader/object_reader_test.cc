// The loader's side of an object type's `read` hook
// (swarm/loader/object_reader.cc): lists of vectors, names, nested maps and
// mesh files read from one model-file entry, each mistake at its place.
#include "swarm/loader/object_reader.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "swarm/loader/mesh.h"
#include "tests/swarm/loader/yaml_file.h"

namespace swarmsim::loader {
namespace {

namespace fs = std::filesystem;
using testing::ErrorOf;
using testing::Root;
using testing::Yaml;
using testing::YamlDir;

// One entry (`yaml`) read through a FieldsObjectReader, with the world
// parameter n = 3.
struct Entry {
  explicit Entry(const std::string& yaml)
      : file(Yaml(yaml)),
        fields(file, Root(file), "object 'x'"),
        reader(values, fields, &meshes, nullptr) {}
  ~Entry() { fs::remove_all(YamlDir()); }
  ParameterSet world{{"n", 3.0}};
  Expressions expressions;
  YamlFile file;
  Fields fields;
  ValueReader values{file, &expressions, Scope{&world, nullptr, nullptr}};
  MeshCache meshes;
  FieldsObjectReader reader;
  std::string Where(const std::string& key) const { return file.Where(fields.Get(key).mark); }
};

TEST(ObjectReaderTest, VectorListsHaveTheirLeastCount) {
  const Entry e("points: [[0, 0, 0], [1, $n, 2]]\none: [[1, 2, 3]]\nflat: [1, 2, 3]\n");
  const std::vector<Vec3> points = e.reader.Vector3List("points", 2, kAnyNumber, true);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[1].y, 3) << "values may use parameters";
  EXPECT_EQ(ErrorOf([&] { e.reader.Vector3List("one", 2, kAnyNumber, true); }),
            e.Where("one") +
                ": 'one' needs at least 2 [x, y, z] lists, e.g. [[0, 0, 0], "
                "[1, 0, 0]] (got 1)");
  EXPECT_EQ(ErrorOf([&] { e.reader.Vector3List("flat", 1, kAnyNumber, true); }),
            e.file.name() +
                ":3:8: 'flat[0]' must be a list of 3 numbers, e.g. [1, 2, 3] (got "
                "\"1\")");
  EXPECT_TRUE(e.reader.Vector3List("absent", 2, kAnyNumber, false).empty());
  EXPECT_EQ(ErrorOf([&] { e.reader.Vector3List("absent", 2, kAnyNumber, true); }),
            e.file.name() + ":1:1: 'absent' is required in object 'x'");
}

TEST(ObjectReaderTest, AnElementsMistakeIsNamedAtTheElement) {
  const Entry e("points: [[0, 0, 0], [1, 1, 1]]\nscalar: 5\n");
  EXPECT_EQ(ErrorOf([&] { e.reader.FailAtElement("points", 1, "is too far"); }),
            e.file.name() + ":1:21: is too far");
  // Past the end, or not a list: at the key's value.
  EXPECT_EQ(ErrorOf([&] { e.reader.FailAtElement("points", 5, "is missing"); }),
            e.Where("points") + ": is missing");
}

TEST(ObjectReaderTest, NamesAreOneOrAListOfAtMostTheirCount) {
  const Entry e("one: left\nmany: [a, $n, b]\nfour: [a, b, c, d]\n");
  EXPECT_EQ(e.reader.Strings("one", 3, true), std::vector<std::string>{"left"});
  EXPECT_EQ(e.reader.Strings("many", 3, true), (std::vector<std::string>{"a", "3", "b"}));
  EXPECT_EQ(ErrorOf([&] { e.reader.Strings("four", 3, true); }),
            e.Where("four") + ": 'four' takes at most 3 names (got 4)");
  EXPECT_TRUE(e.reader.Strings("absent", 3, false).empty());
}

TEST(ObjectReaderTest, ItemsAreReadersOfTheirOwnMaps) {
  const Entry e("wheels:\n  - {radius: 0.1, side: left}\n  - {radius: $n, sied: right}\n");
  const auto items = e.reader.Items("wheels");
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(items[0]->Number("radius", kPositive, true), 0.1);
  EXPECT_EQ(items[0]->String("side", true), "left");
  EXPECT_EQ(items[1]->Number("radius", kPositive, true), 3);
  EXPECT_EQ(ErrorOf([&] {
              items[1]->Expect(std::vector<std::string>{"radius", "side"});
            }),
            e.file.name() +
                ":3:18: unknown key 'sied' in wheels[1] of object 'x'; did you mean "
                "'side'?");
  EXPECT_TRUE(e.reader.Items("absent").empty());
}

TEST(ObjectReaderTest, MeshesAreReadBesideTheFileAndShared) {
  fs::create_directories(YamlDir());
  fs::copy_file(fs::path(SWARMSIM_SOURCE_DIR) / "tests/data/meshes/unit_cube.stl",
                YamlDir() / "cube.stl", fs::copy_options::overwrite_existing);
  const Entry e("file: cube.stl\nagain: cube.stl\nnone: ''\nmissing: nowhere.stl\n");
  const auto mesh = e.reader.Mesh("file", {1, 1, 1});
  ASSERT_NE(mesh, nullptr);
  EXPECT_FALSE(mesh->triangles().empty());
  EXPECT_EQ(e.reader.Mesh("again", {1, 1, 1}), mesh) << "read once, shared";
  EXPECT_EQ(e.meshes.files_read(), 1u);
  const auto twice = e.reader.Mesh("again", {2, 2, 2});
  EXPECT_NEAR(twice->hi().x - twice->lo().x, 2 * (mesh->hi().x - mesh->lo().x), 1e-9);
  EXPECT_EQ(ErrorOf([&] {
              e.reader.Mesh("none", {1, 1, 1});
            }),
            e.Where("none") + ": 'none' must be a mesh file name (.stl or .obj)");
  EXPECT_EQ(ErrorOf([&] {
              e.reader.Mesh("missing", {1, 1, 1});
            }).rfind(e.Where("missing") + ": mesh file 'nowhere.stl' ", 0),
            0u)
      << ErrorOf([&] {
           e.reader.Mesh("missing", {1, 1, 1});
         });
}

}  // namespace
}  // namespace swarmsim::loader
