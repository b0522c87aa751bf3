#include "swarm/record/chunk_json.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "framework/error.h"
#include "swarm/record/format.h"

namespace swarmsim::record {
namespace {

using nlohmann::json;
constexpr int64_t kMaxInt = std::numeric_limits<int64_t>::max();

// A scalar as the parser read it.
struct Scalar {
  enum class Kind { kNull, kBool, kInteger, kNumber, kString };
  Kind kind = Kind::kNull;
  bool boolean = false;
  bool integral = false;  // a whole number that fits in int64_t (then `integer`)
  int64_t integer = 0;
  double number = 0;  // any number
  std::string_view text;

  bool is_number() const { return kind == Kind::kInteger || kind == Kind::kNumber; }
  // For messages: 1000000, 0.5, "abc" (cut at 40 bytes), true, null.
  std::string Describe() const {
    switch (kind) {
      case Kind::kNull: return "null";
      case Kind::kBool: return boolean ? "true" : "false";
      case Kind::kInteger:
        if (integral) return std::to_string(integer);
        [[fallthrough]];
      case Kind::kNumber: {
        std::ostringstream out;
        out.precision(17);
        out << number;
        return out.str();
      }
      case Kind::kString:
        return "\"" + std::string(text.substr(0, 40)) + (text.size() > 40 ? "...\"" : "\"");
    }
    return "";
  }
};

// The place of a value: one part per open container.
struct PathPart {
  bool in_list = false;
  int64_t index = -1;  // in a list: the element's index
  int64_t count = 0;   // in a list: elements begun so far
  std::string key;     // in a map: the element's key
};

// A container a chunk's layout requires at a place ("*": any list index).
struct Shape {
  std::vector<std::string_view> pattern;
  bool list = false;
};

// The handler nlohmann::json::sax_parse drives: follows each value's place,
// limits nesting (kMaxJsonDepth), checks the containers `shapes` requires,
// turns a syntax error into a message with its byte, and hands scalars,
// container starts and ends to the chunk's reader below.
class PathReader {
 public:
  PathReader(const std::string& where, std::vector<Shape> shapes)
      : where_(where), shapes_(std::move(shapes)) {}
  virtual ~PathReader() = default;

  // Throws Error for broken JSON or what the reader refuses.
  void Parse(std::string_view text) {
    json::sax_parse(text.begin(), text.end(), this);
    if (!seen_value_) Fail("it holds no JSON value");
  }

  // nlohmann::json's SAX interface.
  bool null() { return Value({}); }
  bool boolean(bool b) {
    Scalar s;
    s.kind = Scalar::Kind::kBool;
    s.boolean = b;
    return Value(s);
  }
  bool number_integer(json::number_integer_t n) {
    Scalar s;
    s.kind = Scalar::Kind::kInteger;
    s.integral = true;
    s.integer = n;
    s.number = static_cast<double>(n);
    return Value(s);
  }
  bool number_unsigned(json::number_unsigned_t n) {
    Scalar s;
    s.kind = Scalar::Kind::kInteger;
    s.integral = n <= static_cast<uint64_t>(kMaxInt);
    s.integer = s.integral ? static_cast<int64_t>(n) : 0;
    s.number = static_cast<double>(n);
    return Value(s);
  }
  bool number_float(json::number_float_t x, const json::string_t&) {
    Scalar s;
    s.kind = Scalar::Kind::kNumber;
    s.number = x;
    // 2.0 is a whole number; 1e300 is not an int64_t.
    s.integral = std::isfinite(x) && x == std::floor(x) && std::abs(x) < 9.2e18;
    s.integer = s.integral ? static_cast<int64_t>(x) : 0;
    return Value(s);
  }
  bool string(json::string_t& text) {
    Scalar s;
    s.kind = Scalar::Kind::kString;
    s.text = text;
    return Value(s);
  }
  bool binary(json::binary_t&) { return Value({}); }  // not in JSON text
  bool start_object(std::size_t) { return Open(false); }
  bool start_array(std::size_t) { return Open(true); }
  bool key(json::string_t& key) {
    path_.back().key = key;
    return true;
  }
  bool end_object() { return Close(); }
  bool end_array() { return Close(); }
  bool parse_error(std::size_t position, const std::string&, const json::exception& e) {
    // "[json.exception.parse_error.101] parse error at line 1, column 5: syntax
    // error while parsing value - invalid literal; last read: 'x'": the words
    // after the place, with the byte instead.
    std::string what = e.what();
    if (const size_t colon = what.find(": "); colon != std::string::npos)
      what = what.substr(colon + 2);
    Fail("its JSON text is broken at byte " + std::to_string(position > 0 ? position - 1 : 0) +
         " (" + what + ")");
  }

 protected:
  virtual void OnScalar(const Scalar& value) = 0;
  virtual void OnOpen(bool /*list*/) {}  // path(): the container's place
  virtual void OnClose(bool /*list*/) {}

  // Whether the current place is `pattern` (names for keys, "*" any index).
  bool At(std::initializer_list<std::string_view> pattern) const { return Matches(pattern); }
  // The index at depth `depth` of the current place (a list's element).
  int64_t Index(size_t depth) const { return path_[depth].index; }
  size_t Depth() const { return path_.size(); }
  // "robots[0].first"; "the top level" for the root.
  std::string PathText() const {
    std::string text;
    for (const PathPart& part : path_) {
      if (part.in_list) {
        text += "[" + std::to_string(part.index) + "]";
      } else {
        if (!text.empty()) text += ".";
        text += part.key;
      }
    }
    return text.empty() ? "the top level" : text;
  }
  [[noreturn]] void Fail(const std::string& what) const { throw Error(where_ + ": " + what); }
  // The value as an integer in lo..hi, or the error naming its place.
  int64_t Integer(const Scalar& value, int64_t lo, int64_t hi) const {
    if (!value.integral || value.integer < lo || value.integer > hi)
      Fail(PathText() + " is " + value.Describe() + ", expected a whole number from " +
           std::to_string(lo) + (hi == kMaxInt ? " up" : " to " + std::to_string(hi)));
    return value.integer;
  }
  double Number(const Scalar& value) const {
    if (!value.is_number()) Fail(PathText() + " is " + value.Describe() + ", expected a number");
    return value.number;
  }

  const std::string& where_;

 private:
  template <typename Pattern>
  bool Matches(const Pattern& pattern) const {
    if (pattern.size() != path_.size()) return false;
    size_t i = 0;
    for (const std::string_view name : pattern) {
      const PathPart& part = path_[i++];
      if (name == "*" ? !part.in_list : part.in_list || part.key != name) return false;
    }
    return true;
  }
  // The shape required where the value about to begin is, if any.
  const Shape* Required() const {
    for (const Shape& shape : shapes_)
      if (Matches(shape.pattern)) return &shape;
    return nullptr;
  }
  void BeginValue() {
    seen_value_ = true;
    if (!path_.empty() && path_.back().in_list) path_.back().index = path_.back().count++;
  }
  bool Value(const Scalar& value) {
    BeginValue();
    if (const Shape* shape = Required())
      Fail(PathText() + " is " + value.Describe() + ", expected " +
           (shape->list ? "a list" : "a map"));
    OnScalar(value);
    return true;
  }
  bool Open(bool list) {
    BeginValue();
    if (const Shape* shape = Required(); shape && shape->list != list)
      Fail(PathText() + " is " + (list ? "a list" : "a map") + ", expected " +
           (shape->list ? "a list" : "a map"));
    if (static_cast<int>(path_.size()) >= kMaxJsonDepth)
      Fail(PathText() + " is nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    OnOpen(list);
    PathPart part;
    part.in_list = list;
    path_.push_back(std::move(part));
    return true;
  }
  bool Close() {
    const bool list = path_.back().in_list;
    path_.pop_back();
    OnClose(list);
    return true;
  }

  std::vector<Shape> shapes_;
  std::vector<PathPart> path_;
  bool seen_value_ = false;
};

// --- Header ------------------------------------------------------------------------

class HeaderReader : public PathReader {
 public:
  explicit HeaderReader(const std::string& where) : PathReader(where, {}) {}
  HeaderFields fields;

  void Finish() {
    if (fields.has_paint) {
      if (!paint_width_ || !paint_height_) {
        Problem("paint has no width and height");
      } else if (uint64_t{fields.paint_width} * fields.paint_height > kMaxPaintCells) {
        Problem("paint is " + std::to_string(fields.paint_width) + " x " +
                std::to_string(fields.paint_height) + " cells, more than the " +
                std::to_string(kMaxPaintCells) + " a recording may hold");
      }
    }
    fields.has_version = version_length_ >= 2 && major_integral_;
  }

 private:
  void Problem(const std::string& what) {
    if (fields.problem.empty()) fields.problem = what;
  }
  // An integer in lo..hi, or a problem (0).
  int64_t Whole(const Scalar& value, int64_t lo, int64_t hi) {
    if (value.integral && value.integer >= lo && value.integer <= hi) return value.integer;
    Problem(PathText() + " is " + value.Describe() + ", expected a whole number from " +
            std::to_string(lo) + " to " + std::to_string(hi));
    return 0;
  }
  void OnScalar(const Scalar& v) override {
    constexpr int64_t kMaxSide = std::numeric_limits<int32_t>::max();
    if (At({"format"}) && v.kind == Scalar::Kind::kString) {
      fields.format = v.text;
    } else if (At({"version", "*"})) {
      version_length_ = std::max<int64_t>(version_length_, Index(1) + 1);
      if (Index(1) == 0 && v.integral && std::abs(v.integer) < (1 << 30)) {
        major_integral_ = true;
        fields.version_major = static_cast<int>(v.integer);
      } else if (Index(1) == 1 && v.integral && std::abs(v.integer) < (1 << 30)) {
        fields.version_minor = static_cast<int>(v.integer);
      }
    } else if (At({"paint"})) {
      if (v.kind != Scalar::Kind::kNull)
        Problem("paint is " + v.Describe() + ", expected a map or null");
    } else if (At({"paint", "width"})) {
      paint_width_ = true;
      fields.paint_width = static_cast<uint32_t>(Whole(v, 1, kMaxSide));
    } else if (At({"paint", "height"})) {
      paint_height_ = true;
      fields.paint_height = static_cast<uint32_t>(Whole(v, 1, kMaxSide));
    } else if (At({"paint", "background", "*"})) {
      if (!v.is_number() || Index(2) > 2)
        Problem("paint.background is not three numbers from 0 to 1");
      else
        fields.paint_background[Index(2)] = std::clamp(v.number, 0.0, 1.0);
    } else if (At({"metrics", "*"})) {
      if (v.kind == Scalar::Kind::kString)
        fields.metrics.emplace_back(v.text);
      else
        Problem(PathText() + " is " + v.Describe() + ", expected a metric's name");
    } else if (At({"metrics"}) || At({"paint", "background"})) {
      Problem(PathText() + " is " + v.Describe() + ", expected a list");
    }
  }
  void OnOpen(bool list) override {
    if (Depth() == 0) {
      fields.is_object = !list;
    } else if (At({"paint"})) {
      if (list) Problem("paint is a list, expected a map or null");
      fields.has_paint = !list;
    } else if (At({"metrics"})) {
      if (!list) Problem("metrics is a map, expected a list of names");
      fields.metrics.clear();
    } else if (At({"metrics", "*"})) {
      Problem(PathText() + " is a " + (list ? "list" : "map") + ", expected a metric's name");
    } else if (At({"version"})) {
      version_length_ = 0;
      major_integral_ = false;
    }
  }

  int64_t version_length_ = 0;
  bool major_integral_ = false;
  bool paint_width_ = false, paint_height_ = false;
};

// --- Scene -------------------------------------------------------------------------

// A robot as listed, with its place in the list and its template.
struct RobotEntry {
  SceneRobot robot;
  int64_t position = 0;    // in "robots"
  int64_t template_ = -1;  // index into "templates"
};

class SceneReader : public PathReader {
 public:
  explicit SceneReader(const std::string& where)
      : PathReader(where, {{{}, false},
                           {{"templates"}, true},
                           {{"templates", "*"}, false},
                           {{"templates", "*", "objects"}, true},
                           {{"templates", "*", "objects", "*"}, false},
                           {{"robots"}, true},
                           {{"robots", "*"}, false},
                           {{"objects"}, true},
                           {{"objects", "*"}, false},
                           {{"meshes"}, true},
                           {{"meshes", "*"}, false},
                           {{"meshes", "*", "vertices"}, true},
                           {{"meshes", "*", "triangles"}, true},
                           {{"meshes", "*", "colors"}, true}}) {}

  SceneFields Finish();

 private:
  void OnScalar(const Scalar& v) override;
  void OnOpen(bool list) override;
  void OnClose(bool list) override;

  std::optional<uint64_t> object_count_;
  bool has_templates_ = false, has_robots_ = false;
  std::vector<uint64_t> template_sizes_;  // objects of each template
  // The robot being read, then every robot read.
  RobotEntry robot_;
  bool robot_has_[4] = {};  // index, first, count, template
  std::vector<RobotEntry> robots_;
  // The ids of the objects outside robots, by their place in "objects".
  int64_t object_id_ = -1;
  std::vector<uint64_t> object_ids_;
  // The largest parent id and mesh index anywhere, with where they are.
  int64_t max_parent_ = -1, max_mesh_ = -1;
  std::string max_parent_at_, max_mesh_at_;
  // The mesh being read, and the meshes read.
  uint64_t vertices_ = 0, triangles_ = 0, colors_ = 0;
  int64_t max_vertex_ = -1;
  uint64_t mesh_count_ = 0;
};

void SceneReader::OnScalar(const Scalar& v) {
  if (At({"object_count"})) {
    object_count_ = static_cast<uint64_t>(Integer(v, 0, kMaxInt));
  } else if (At({"templates", "*", "objects", "*", "parent"})) {
    // Hierarchy order: a parent comes before its children; the root has none.
    const int64_t k = Index(3);
    Integer(v, -1, k - 1);
  } else if (At({"templates", "*", "objects", "*", "mesh"}) || At({"objects", "*", "mesh"})) {
    if (const int64_t mesh = Integer(v, 0, kMaxInt); mesh > max_mesh_) {
      max_mesh_ = mesh;
      max_mesh_at_ = PathText();
    }
  } else if (At({"robots", "*", "index"})) {
    robot_.robot.index = Integer(v, 0, kMaxInt);
    robot_has_[0] = true;
  } else if (At({"robots", "*", "first"})) {
    robot_.robot.first = static_cast<uint64_t>(Integer(v, 0, kMaxInt));
    robot_has_[1] = true;
  } else if (At({"robots", "*", "count"})) {
    robot_.robot.count = static_cast<uint64_t>(Integer(v, 1, kMaxInt));
    robot_has_[2] = true;
  } else if (At({"robots", "*", "template"})) {
    robot_.template_ = Integer(v, 0, kMaxInt);
    robot_has_[3] = true;
  } else if (At({"objects", "*", "id"})) {
    object_id_ = Integer(v, 0, kMaxInt);
  } else if (At({"objects", "*", "parent"})) {
    if (const int64_t parent = Integer(v, -1, kMaxInt); parent > max_parent_) {
      max_parent_ = parent;
      max_parent_at_ = PathText();
    }
  } else if (At({"meshes", "*", "vertices", "*"})) {
    Number(v);
    ++vertices_;
  } else if (At({"meshes", "*", "triangles", "*"})) {
    max_vertex_ = std::max(max_vertex_, Integer(v, 0, kMaxInt));
    ++triangles_;
  } else if (At({"meshes", "*", "colors", "*"})) {
    Number(v);
    ++colors_;
  }
}

void SceneReader::OnOpen(bool) {
  // A key given twice counts once: the last list wins, as in a JSON document.
  if (At({"templates"})) {
    has_templates_ = true;
    template_sizes_.clear();
  } else if (At({"templates", "*"})) {
    template_sizes_.push_back(0);
  } else if (At({"templates", "*", "objects"})) {
    template_sizes_.back() = 0;
  } else if (At({"templates", "*", "objects", "*"})) {
    ++template_sizes_.back();
  } else if (At({"robots"})) {
    has_robots_ = true;
    robots_.clear();
  } else if (At({"robots", "*"})) {
    robot_ = RobotEntry{};
    robot_.position = Index(1);
    std::fill(std::begin(robot_has_), std::end(robot_has_), false);
  } else if (At({"objects"})) {
    object_ids_.clear();
  } else if (At({"objects", "*"})) {
    object_id_ = -1;
  } else if (At({"meshes"})) {
    mesh_count_ = 0;
  } else if (At({"meshes", "*"})) {
    vertices_ = triangles_ = colors_ = 0;
    max_vertex_ = -1;
  }
}

void SceneReader::OnClose(bool) {
  if (At({"robots", "*"})) {
    static constexpr const char* kFields[4] = {"index", "first", "count", "template"};
    for (int i = 0; i < 4; ++i)
      if (!robot_has_[i]) Fail(PathText() + " has no " + kFields[i]);
    robots_.push_back(robot_);
  } else if (At({"objects", "*"})) {
    if (object_id_ < 0) Fail(PathText() + " has no id");
    object_ids_.push_back(static_cast<uint64_t>(object_id_));
  } else if (At({"meshes", "*"})) {
    const std::string mesh = PathText();
    if (vertices_ % 3 != 0 || triangles_ % 3 != 0)
      Fail(mesh + " has " + std::to_string(vertices_) + " vertex coordinates and " +
           std::to_string(triangles_) + " triangle corners, expected multiples of 3");
    if (max_vertex_ >= 0 && static_cast<uint64_t>(max_vertex_) >= vertices_ / 3)
      Fail(mesh + ".triangles names vertex " + std::to_string(max_vertex_) + ", but it has " +
           std::to_string(vertices_ / 3) + " vertices");
    if (colors_ != 0 && colors_ != triangles_)
      Fail(mesh + ".colors has " + std::to_string(colors_) + " numbers, expected " +
           std::to_string(triangles_) + " (an RGB per triangle) or none");
    ++mesh_count_;
  }
}

SceneFields SceneReader::Finish() {
  if (!object_count_) Fail("it has no object_count");
  if (!has_templates_) Fail("it has no templates");
  if (!has_robots_) Fail("it has no robots");
  const uint64_t n = *object_count_;
  const std::string objects = " the scene's " + std::to_string(n) + " objects";
  // The keyframe after a scene holds every object's pose, and a chunk holds
  // at most kMaxChunkRawBytes.
  if (n > kMaxChunkRawBytes / kPoseBytes)
    Fail("object_count is " + std::to_string(n) + ", more than the " +
         std::to_string(kMaxChunkRawBytes / kPoseBytes) + " a keyframe can hold");
  if (max_mesh_ >= 0 && static_cast<uint64_t>(max_mesh_) >= mesh_count_)
    Fail(max_mesh_at_ + " is " + std::to_string(max_mesh_) + ", but the scene has " +
         std::to_string(mesh_count_) + " meshes");
  if (max_parent_ >= 0 && static_cast<uint64_t>(max_parent_) >= n)
    Fail(max_parent_at_ + " is " + std::to_string(max_parent_) + ", outside" + objects);

  // Every id 0 .. n-1 belongs to exactly one robot's range or one object.
  struct Range {  // ids first .. first + count - 1, and who claims them
    uint64_t first, count;
    std::string owner;
  };
  std::vector<Range> ranges;
  ranges.reserve(robots_.size() + object_ids_.size());
  for (const RobotEntry& r : robots_) {
    const std::string robot = "robots[" + std::to_string(r.position) + "]";
    if (static_cast<uint64_t>(r.template_) >= template_sizes_.size())
      Fail(robot + ".template is " + std::to_string(r.template_) + ", but the scene has " +
           std::to_string(template_sizes_.size()) + " templates");
    if (r.robot.count != template_sizes_[r.template_])
      Fail(robot + ".count is " + std::to_string(r.robot.count) + ", but its template " +
           std::to_string(r.template_) + " has " + std::to_string(template_sizes_[r.template_]) +
           " objects");
    if (r.robot.first >= n || r.robot.count > n - r.robot.first)
      Fail(robot + ".first is " + std::to_string(r.robot.first) + " and its count " +
           std::to_string(r.robot.count) + ": ids outside" + objects);
    ranges.push_back({r.robot.first, r.robot.count, robot});
  }
  for (size_t i = 0; i < object_ids_.size(); ++i) {
    const std::string object = "objects[" + std::to_string(i) + "]";
    if (object_ids_[i] >= n)
      Fail(object + ".id is " + std::to_string(object_ids_[i]) + ", outside" + objects);
    ranges.push_back({object_ids_[i], 1, object});
  }
  std::sort(ranges.begin(), ranges.end(),
            [](const Range& a, const Range& b) { return a.first < b.first; });
  uint64_t next = 0;  // the first id not yet claimed
  for (size_t i = 0; i < ranges.size(); ++i) {
    if (ranges[i].first < next)
      Fail(ranges[i].owner + " claims id " + std::to_string(ranges[i].first) + ", as does " +
           ranges[i - 1].owner);
    if (ranges[i].first > next)
      Fail("ids " + std::to_string(next) + " to " + std::to_string(ranges[i].first - 1) +
           " belong to no robot or object");
    next = ranges[i].first + ranges[i].count;
  }
  if (next != n)
    Fail("object_count is " + std::to_string(n) + ", but its robots and objects have " +
         std::to_string(next) + " ids");

  // Robot indices name one robot each.
  SceneFields fields;
  fields.object_count = n;
  fields.robots.reserve(robots_.size());
  for (const RobotEntry& r : robots_) fields.robots.push_back(r.robot);
  std::vector<int64_t> indices;
  indices.reserve(robots_.size());
  for (const RobotEntry& r : robots_) indices.push_back(r.robot.index);
  std::sort(indices.begin(), indices.end());
  if (const auto twice = std::adjacent_find(indices.begin(), indices.end()); twice != indices.end())
    Fail("two robots have the index " + std::to_string(*twice));
  return fields;
}

// --- End ---------------------------------------------------------------------------

class EndReader : public PathReader {
 public:
  explicit EndReader(const std::string& where) : PathReader(where, {{{}, false}}) {}
  EndFields fields;

 private:
  void OnScalar(const Scalar& v) override {
    const bool status = At({"status"}), error = At({"error"});
    if (!status && !error) return;
    if (v.kind != Scalar::Kind::kString)
      Fail(PathText() + " is " + v.Describe() + ", expected a string");
    (status ? fields.status : fields.error) = v.text;
  }
};

}  // namespace

HeaderFields ParseHeaderJson(std::string_view text, const std::string& where) {
  HeaderReader reader(where);
  reader.Parse(text);
  reader.Finish();
  return std::move(reader.fields);
}

SceneFields ParseSceneJson(std::string_view text, const std::string& where) {
  SceneReader reader(where);
  reader.Parse(text);
  return reader.Finish();
}

EndFields ParseEndJson(std::string_view text, const std::string& where) {
  EndReader reader(where);
  reader.Parse(text);
  return std::move(reader.fields);
}

}  // namespace swarmsim::record
