// YAML reading helpers for the world and model loaders: positions in
// messages (file:line:column, 1-based), key checking with "did you mean"
// suggestions, and file reading that names who referenced a missing file.
//
// yaml-cpp types stay in the loader's files (swarm/loader/*.h are internal
// to the loader; the public API is world_loader.h).
#pragma once

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "framework/display_path.h"
#include "framework/suggest.h"

namespace swarmsim::loader {

// EditDistance and Suggest ("; did you mean 'radius'?"), shared with the
// script host (framework/suggest.h).
using swarmsim::EditDistance;
using swarmsim::Suggest;

// A path as the user would recognise it (framework/display_path.h).
using swarmsim::DisplayPath;

// A YAML file being read: its name for messages and its parsed root.
class YamlFile {
 public:
  // Reads and parses `path`. A missing or unreadable file throws
  // swarmsim::Error naming the file and `referenced_by` (e.g.
  // "worlds/x.yaml:12:5: model file 'models/footbot.yaml' not found (looked for
  // worlds/models/footbot.yaml)"); a syntax error keeps its line and column.
  // `kind` names the file in messages ("world file", "model file").
  static YamlFile Load(const std::filesystem::path& path, std::string_view kind,
                       const std::string& referenced_by, const std::string& reference_text);

  const std::string& name() const { return name_; }            // for messages
  const std::filesystem::path& path() const { return path_; }  // for opening
  const YAML::Node& root() const { return root_; }

  // "file:line:column" (1-based); "file" alone for a null mark.
  std::string Where(const YAML::Mark& mark) const;
  [[noreturn]] void Fail(const YAML::Mark& mark, const std::string& message) const;

 private:
  std::string name_;
  std::filesystem::path path_;
  YAML::Node root_;
};

// Reads a whole file; throws swarmsim::Error "<where>: <kind> 'text' not
// found (looked for <path>)" (or the OS's reason) when it cannot.
std::string ReadFileOrThrow(const std::filesystem::path& path, std::string_view kind,
                            const std::string& where, const std::string& text);

// One value in a mapping (or an element of a list), with what messages
// need: its name ("radius", "position[2]") and where it is.
struct Field {
  std::string name;
  YAML::Node node;
  YAML::Mark mark;      // the value's position, or its key's when the value is empty
  YAML::Mark key_mark;  // the key's position (the list's for an element)

  Field() = default;
  Field(std::string name_, YAML::Node node_, YAML::Mark mark_, YAML::Mark key_mark_)
      : name(std::move(name_)), node(std::move(node_)), mark(mark_), key_mark(key_mark_) {}
  Field(const Field&) = default;
  // yaml-cpp's Node::operator= writes the right side into the node the left
  // side refers to, i.e. into the parsed document: `field = other` would edit
  // a model file's tree that later copies are read from again. A Field
  // assignment rebinds instead (Node::reset).
  Field& operator=(const Field& other) {
    name = other.name;
    node.reset(other.node);
    mark = other.mark;
    key_mark = other.key_mark;
    return *this;
  }
  bool present() const { return node.IsDefined() && !node.IsNull(); }
};

// How a value is described in "(got ...)": the scalar text quoted, or "a
// list", "a mapping", "nothing".
std::string Describe(const YAML::Node& node);

// The keys of one YAML mapping, checked: `node` must be a mapping with
// scalar keys, each at most once, all among `known`. `what` names the
// mapping in messages ("unknown key 'raduis' in shape 'body'; did you mean
// 'radius'?").
class Fields {
 public:
  Fields(const YamlFile& file, const Field& mapping, std::string what);
  // A value read as a mapping with the one key `only.name` (a bare name in
  // a list of maps: `metrics: [covered_area]`).
  static Fields Single(const YamlFile& file, Field only, std::string what);
  // Throws for a key not in `known`.
  void Expect(std::span<const std::string> known) const;
  void Expect(std::initializer_list<std::string_view> known) const;

  bool Has(std::string_view key) const;
  // The field (not present() when absent).
  Field Get(std::string_view key) const;
  // Throws "'key' is required in <what>" when absent or empty.
  Field Require(std::string_view key) const;
  const std::string& what() const { return what_; }
  const YAML::Mark& mark() const { return mark_; }
  std::vector<std::string> keys() const;
  std::span<const Field> fields() const { return fields_; }

 private:
  Fields(const YamlFile& file, std::string what, YAML::Mark mark)
      : file_(file), what_(std::move(what)), mark_(mark) {}

  const YamlFile& file_;
  std::string what_;
  YAML::Mark mark_;
  std::vector<Field> fields_;
};

// The elements of a YAML list (`what` names it in messages). A missing or
// empty value gives no elements.
std::vector<Field> ListElements(const YamlFile& file, const Field& list, std::string_view what);

}  // namespace swarmsim::loader
