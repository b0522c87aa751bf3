// The loader's YAML reading (swarm/loader/yaml.cc): files that cannot be read
// named with who referenced them, syntax errors at their line and column,
// keys checked with a suggestion, lists and values described in messages.
#include "swarm/loader/yaml.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/swarm/loader/yaml_file.h"

namespace swarmsim::loader {
namespace {

namespace fs = std::filesystem;
using testing::ErrorOf;
using testing::Root;
using testing::Yaml;
using testing::YamlDir;

TEST(YamlTest, AFileThatCannotBeReadIsNamedWithWhoReferencedIt) {
  const fs::path missing = YamlDir() / "models" / "x.yaml";
  const auto load = [](const fs::path& path) {
    return ErrorOf([&] { YamlFile::Load(path, "model file", "w.yaml:12:5", "models/x.yaml"); });
  };
  EXPECT_EQ(load(missing), "w.yaml:12:5: model file 'models/x.yaml' not found (looked for " +
                               fs::absolute(missing).lexically_normal().string() +
                               "; a path in a file is relative to that file's folder)");
  fs::create_directories(YamlDir() / "folder.yaml");
  EXPECT_EQ(load(YamlDir() / "folder.yaml"),
            "w.yaml:12:5: model file 'models/x.yaml' is a directory, not a file (looked for " +
                DisplayPath(YamlDir() / "folder.yaml") + ")");
  ASSERT_EQ(::mkfifo((YamlDir() / "fifo.yaml").c_str(), 0600), 0);
  EXPECT_EQ(load(YamlDir() / "fifo.yaml"),
            "w.yaml:12:5: model file 'models/x.yaml' is not a regular file (looked for " +
                DisplayPath(YamlDir() / "fifo.yaml") + ")");
  // Without a referrer: the kind and the path alone.
  EXPECT_EQ(ErrorOf([&] { YamlFile::Load(missing, "world file", "", DisplayPath(missing)); }),
            "world file '" + DisplayPath(missing) + "' not found");
  fs::remove_all(YamlDir());
}

TEST(YamlTest, SyntaxErrorsKeepTheirLineAndColumn) {
  const std::string unclosed = ErrorOf([] { Yaml("a: [1, 2\nb: 3\n"); });
  EXPECT_EQ(unclosed.rfind(DisplayPath(YamlDir() / "w.yaml") + ":", 0), 0u) << unclosed;
  EXPECT_NE(unclosed.find(": YAML syntax error: "), std::string::npos) << unclosed;
  EXPECT_EQ(unclosed.find("tabs"), std::string::npos) << unclosed;
  // A tab in the indentation says so.
  const std::string tab = ErrorOf([] { Yaml("a:\n\tb: 1\n"); });
  EXPECT_NE(tab.find(DisplayPath(YamlDir() / "w.yaml") + ":2:"), std::string::npos) << tab;
  EXPECT_NE(tab.find("(YAML does not allow tabs for indentation)"), std::string::npos) << tab;
  fs::remove_all(YamlDir());
}

TEST(YamlTest, ANulByteIsNamedWhereItIs) {
  // yaml-cpp would report "unknown escape character" on the line after it.
  const std::string nul = ErrorOf([] { Yaml(std::string("a: 1\nseed: 3\0\nb: 2\n", 19)); });
  EXPECT_EQ(nul, DisplayPath(YamlDir() / "w.yaml") +
                     ":2:8: a NUL byte (\\0) in the file: a world file is text (was it saved "
                     "by a program that pads with zeros?)");
  const std::string first = ErrorOf([] { Yaml(std::string("\0a: 1\n", 7)); });
  EXPECT_NE(first.find("w.yaml:1:1: a NUL byte"), std::string::npos) << first;
  fs::remove_all(YamlDir());
}

// A quote left open read the rest of the file into one string: the run
// went on with no arena and no models (robots 0, exit 0).
TEST(YamlTest, AQuoteLeftOpenIsNamedWhereItOpens) {
  const std::string single = ErrorOf(
      [] { Yaml("simulation:\n  steps: 2\nparameters:\n  robots: 'abc\narena:\n  size: 3\n"); });
  EXPECT_EQ(single, DisplayPath(YamlDir() / "w.yaml") +
                        ":4:11: the value quoted with ' here runs on into line 5 ('arena:'), "
                        "which is indented no deeper than its own: is its closing ' missing?");
  const std::string dual = ErrorOf([] { Yaml("- name: \"x\n- name: y\n"); });
  EXPECT_NE(dual.find("w.yaml:1:9: the value quoted with \" here runs on into line 2"),
            std::string::npos)
      << dual;
  // Quotes closed (an escaped one inside, '' in single quotes), and a value
  // quoted over lines indented deeper, as YAML allows: read as before.
  EXPECT_EQ(Yaml("a: 'it''s'\nb: \"say \\\"hi\\\"\"\nc: 'one\n  two'\nd: 1\n").root()["c"].Scalar(),
            "one two");
  fs::remove_all(YamlDir());
}

// Nesting past yaml-cpp's depth guard said "YAML syntax error: bad file";
// a loop of symbolic links said "not found".
TEST(YamlTest, DeepNestingAndLinkLoopsSayWhatTheyAre) {
  const std::string deep = ErrorOf([] { Yaml("a: " + std::string(3000, '[')); });
  EXPECT_NE(deep.find("YAML nested too deep here"), std::string::npos) << deep;
  fs::create_directories(YamlDir());
  fs::create_symlink(YamlDir() / "b.yaml", YamlDir() / "a.yaml");
  fs::create_symlink(YamlDir() / "a.yaml", YamlDir() / "b.yaml");
  const std::string loop =
      ErrorOf([] { YamlFile::Load(YamlDir() / "a.yaml", "world file", "", "a.yaml"); });
  EXPECT_EQ(loop, "world file 'a.yaml' is a loop of symbolic links (looked for " +
                      DisplayPath(YamlDir() / "a.yaml") + ")");
  fs::remove_all(YamlDir());
}

// A second document (after ---) was never read: its keys went unchecked.
TEST(YamlTest, ASecondDocumentIsRefused) {
  const std::string second = ErrorOf([] { Yaml("simulation: {steps: 2}\n---\nbogus_key: 1\n"); });
  EXPECT_EQ(second, DisplayPath(YamlDir() / "w.yaml") +
                        ":3:1: a second YAML document (after ---): a world file is one document; "
                        "join the two, or put this one in a file of its own");
  // A leading --- and an empty document after the last are no second one.
  EXPECT_EQ(Yaml("---\na: 1\n").root()["a"].as<int>(), 1);
  EXPECT_EQ(Yaml("a: 1\n---\n").root()["a"].as<int>(), 1);
  fs::remove_all(YamlDir());
}

TEST(YamlTest, PlacesAreOneBasedLineAndColumn) {
  const YamlFile file = Yaml("a: 1\nb:\n  c: here\n");
  EXPECT_EQ(file.name(), DisplayPath(YamlDir() / "w.yaml"));
  EXPECT_EQ(file.Where(file.root()["b"]["c"].Mark()), file.name() + ":3:6");
  EXPECT_EQ(file.Where(YAML::Mark::null_mark()), file.name());
  EXPECT_EQ(ErrorOf([&] { file.Fail(file.root()["a"].Mark(), "no"); }), file.name() + ":1:4: no");
  fs::remove_all(YamlDir());
}

TEST(YamlTest, KeysAreCheckedWithASuggestion) {
  const YamlFile file = Yaml("radius: 1\nheigth: 2\n");
  const Fields fields(file, Root(file), "shape 'body'");
  EXPECT_EQ(fields.keys(), (std::vector<std::string>{"radius", "heigth"}));
  EXPECT_EQ(ErrorOf([&] {
              fields.Expect({"radius", "height"});
            }),
            file.name() + ":2:1: unknown key 'heigth' in shape 'body'; did you mean 'height'?");
  EXPECT_EQ(ErrorOf([&] { fields.Expect({"radius", "heigth"}); }), "");
  EXPECT_TRUE(fields.Has("radius"));
  EXPECT_FALSE(fields.Has("height"));
  const Field radius = fields.Get("radius");
  EXPECT_TRUE(radius.present());
  EXPECT_EQ(file.Where(radius.mark), file.name() + ":1:9");
  EXPECT_EQ(file.Where(radius.key_mark), file.name() + ":1:1");
  EXPECT_FALSE(fields.Get("height").present());
  EXPECT_EQ(ErrorOf([&] { fields.Require("height"); }),
            file.name() + ":1:1: 'height' is required in shape 'body'");
  fs::remove_all(YamlDir());
}

TEST(YamlTest, AMappingHasEachPlainKeyOnce) {
  const YamlFile twice = Yaml("a: 1\nb: 2\na: 3\n");
  EXPECT_EQ(ErrorOf([&] { Fields(twice, Root(twice), "'simulation'"); }),
            twice.name() + ":3:1: duplicate key 'a' in 'simulation' (first given at " +
                twice.name() + ":1:1)");
  const YamlFile list = Yaml("[1, 2]\n");
  EXPECT_EQ(ErrorOf([&] { Fields(list, Root(list), "'simulation'"); }),
            list.name() + ":1:1: 'simulation' must be a mapping of keys to values (got a list)");
  const YamlFile complex = Yaml("? [1, 2]\n: 3\n");
  EXPECT_NE(ErrorOf([&] {
              Fields(complex, Root(complex), "'simulation'");
            }).find("keys in 'simulation' must be plain names (got a list)"),
            std::string::npos);
  fs::remove_all(YamlDir());
}

TEST(YamlTest, ListElementsAreNamedByTheirIndex) {
  const YamlFile file = Yaml("models:\n  - a\n  - b\nnone:\nsome: 3\n");
  const Fields fields(file, Root(file), "the world");
  const std::vector<Field> models = ListElements(file, fields.Get("models"), "models");
  ASSERT_EQ(models.size(), 2u);
  EXPECT_EQ(models[1].name, "models[1]");
  EXPECT_EQ(models[1].node.Scalar(), "b");
  EXPECT_EQ(file.Where(models[1].mark), file.name() + ":3:5");
  EXPECT_TRUE(ListElements(file, fields.Get("none"), "models").empty());
  EXPECT_TRUE(ListElements(file, fields.Get("absent"), "models").empty());
  EXPECT_EQ(ErrorOf([&] { ListElements(file, fields.Get("some"), "model entries"); }),
            file.name() + ":5:7: 'some' must be a list of model entries (got \"3\")");
  fs::remove_all(YamlDir());
}

TEST(YamlTest, ValuesAreDescribedInOnePrintableLine) {
  const YamlFile file = Yaml(
      "list: [1]\nmap: {a: 1}\nnothing:\ntext: \"a\\tb\"\nlong: "
      "abcdefghijklmnopqrstuvwxyz0123456789ABCDEFGHIJ\n");
  EXPECT_EQ(Describe(file.root()["list"]), "a list");
  EXPECT_EQ(Describe(file.root()["map"]), "a mapping");
  EXPECT_EQ(Describe(file.root()["nothing"]), "nothing");
  EXPECT_EQ(Describe(file.root()["absent"]), "nothing");
  EXPECT_EQ(Describe(file.root()["text"]), "\"a?b\"");
  EXPECT_EQ(Describe(file.root()["long"]), "\"abcdefghijklmnopqrstuvwxyz0123456789A...\"");
  fs::remove_all(YamlDir());
}

}  // namespace
}  // namespace swarmsim::loader
