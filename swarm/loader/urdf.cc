#include "swarm/loader/urdf.h"

#include <console_bridge/console.h>
#include <tinyxml2.h>
#include <urdf_model/model.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "framework/display_path.h"
#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/utf8.h"
#include "swarm/loader/urdf_inertia.h"
#include "swarm/loader/urdf_xml.h"
#include "swarm/loader/yaml.h"

namespace swarmsim::loader {

namespace fs = std::filesystem;

namespace {

std::string Num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}

// urdfdom's messages go here instead of the console, for the error text.
class Capture : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR && first_error.empty())
      first_error = text;
  }
  std::string first_error;
};

class Importer {
 public:
  Importer(const fs::path& path, const std::vector<fs::path>& package_path, MeshCache* meshes)
      : path_(path), name_(DisplayPath(path)), package_path_(package_path), meshes_(meshes) {}

  UrdfImport Run(const std::string& where, const std::string& text);

 private:
  [[noreturn]] void Fail(int line, const std::string& message) const {
    throw Error(name_ + (line > 0 ? ":" + std::to_string(line) : "") + ": " + message);
  }
  fs::path ResolveUri(const std::string& uri, int line, const std::string& what);
  std::optional<fs::path> FindPackage(const std::string& package);
  std::optional<ObjectSpec> Geometry(const urdf::Link& link, const urdf::Geometry* geometry,
                                     const urdf::Pose& origin, bool visual, int line,
                                     const Vec3* color);
  MassProperties LinkMass(const urdf::Link& link);
  void GroupMass(const urdf::Link& link, const Pose& X_TL, MassProperties* body,
                 bool* has_geometry);
  MassProperties BodyMass(const urdf::Link& top, bool is_root);
  ObjectSpec LinkObject(const urdf::Link& link, bool top, bool is_root, const Pose& X_PO,
                        const Pose& X_TL);
  std::vector<urdf::JointSharedPtr> ChildJoints(const urdf::Link& link) const;
  void NameObjects();
  const std::string& LinkName(const std::string& link) const { return Named(link_names_, link); }
  const std::string& JointName(const std::string& joint) const {
    return Named(joint_names_, joint);
  }
  // names.at(name), for a name urdfdom gives: a name tinyxml2 read otherwise
  // (the two readers disagreeing, as on a bare '&') is an error naming the
  // file, not std::out_of_range.
  template <class Value>
  const Value& Named(const std::map<std::string, Value>& names, const std::string& name) const {
    const auto it = names.find(name);
    if (it == names.end())
      Fail(0, "'" + ValidUtf8(name) +
                  "' is named otherwise by the XML reader than by urdfdom: check its characters");
    return it->second;
  }

  fs::path path_;
  std::string name_;
  const std::vector<fs::path>& package_path_;
  MeshCache* meshes_;
  UrdfXmlFacts xml_;
  std::map<std::string, std::optional<fs::path>> packages_;
  std::vector<std::string> default_mass_links_;  // bodies' top links given the default mass
  std::vector<std::string> repaired_links_;      // links and bodies whose inertia was balanced
  std::vector<std::string> point_mass_links_;    // bodies of point masses only (their top links)
  // Each link's and joint's object name (NameObjects): unique in the robot.
  std::map<std::string, std::string> link_names_, joint_names_;
  std::vector<std::string> renamed_;  // "link 'a b' is 'a_b_2'", for the warning
  int links_merged_ = 0;              // links joined to their body's top link by fixed joints
  int frames_ = 0, bodies_ = 0, meshes_count_ = 0, visuals_ = 0, collisions_ = 0;
  std::map<std::string, int> mesh_formats_;
  std::map<std::string, int> joint_kinds_;
  std::map<std::string, std::string> merged_joints_;  // UrdfImport::merged_joints
  std::vector<std::string> held_joints_;              // moving joints whose <limit lower> = upper
  int mimics_ = 0;
  double total_mass_ = 0;
};

// --- package:// ---------------------------------------------------------------------

std::string PackageName(const fs::path& package_xml) {
  tinyxml2::XMLDocument doc;
  if (doc.LoadFile(package_xml.string().c_str()) != tinyxml2::XML_SUCCESS) return "";
  const tinyxml2::XMLElement* root = doc.RootElement();
  const tinyxml2::XMLElement* name = root ? root->FirstChildElement("name") : nullptr;
  if (!name || !name->GetText()) return "";
  std::string text = name->GetText();
  text.erase(0, text.find_first_not_of(" \t\r\n"));
  text.erase(text.find_last_not_of(" \t\r\n") + 1);
  return text;
}

std::optional<fs::path> Importer::FindPackage(const std::string& package) {
  if (auto it = packages_.find(package); it != packages_.end()) return it->second;
  std::optional<fs::path> found;
  std::error_code ec;
  auto holds = [&](const fs::path& dir) {
    return fs::is_regular_file(dir / "package.xml", ec) &&
           PackageName(dir / "package.xml") == package;
  };
  // The package holding the URDF file itself first (a URDF naming its own
  // package means that copy, not another of the same name on the path: two
  // robots' copies of example-robot-data sent one to the other's meshes).
  for (fs::path dir = fs::absolute(path_, ec).parent_path(); !found && !dir.empty();
       dir = dir.parent_path()) {
    if (holds(dir)) found = dir;
    if (dir == dir.parent_path()) break;
  }
  // Without package.xml files (the folders as published, copied beside
  // each other): the package folder on the path that holds the URDF.
  const fs::path urdf = fs::weakly_canonical(fs::absolute(path_, ec), ec);
  for (const fs::path& dir : package_path_) {
    if (found) break;
    const fs::path folder = fs::weakly_canonical(dir / package, ec);
    if (!fs::is_directory(folder, ec)) continue;
    const auto [in_folder, in_urdf] =
        std::mismatch(folder.begin(), folder.end(), urdf.begin(), urdf.end());
    if (in_folder == folder.end() && in_urdf != urdf.end()) found = dir / package;
  }
  for (const fs::path& dir : package_path_) {
    if (found) break;
    if (fs::is_directory(dir / package, ec)) {
      found = dir / package;
      break;
    }
    if (holds(dir)) {
      found = dir;
      break;
    }
    // package.xml files one or two levels down (a workspace's src/ folder).
    for (auto it = fs::recursive_directory_iterator(dir, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
      if (it.depth() >= 1) it.disable_recursion_pending();
      if (it->is_directory(ec) && holds(it->path())) {
        found = it->path();
        break;
      }
    }
  }
  packages_[package] = found;
  return found;
}

fs::path Importer::ResolveUri(const std::string& uri, int line, const std::string& what) {
  if (uri.starts_with("package://")) {
    const std::string rest = uri.substr(10);
    const size_t slash = rest.find('/');
    const std::string package = rest.substr(0, slash);
    if (package.empty() || slash == std::string::npos)
      Fail(line, what + ": '" + uri + "' must be package://PACKAGE/PATH");
    const std::optional<fs::path> dir = FindPackage(package);
    if (!dir) {
      std::string searched;
      for (const fs::path& p : package_path_)
        searched += (searched.empty() ? "" : ", ") + DisplayPath(p);
      Fail(line, what + ": cannot resolve package '" + package + "' of '" + uri + "' (searched " +
                     (searched.empty() ? "no package path" : searched) +
                     ", and the folders holding the URDF; give the folder holding the package "
                     "with the world's 'package_path' or --package-path)");
    }
    return *dir / rest.substr(slash + 1);
  }
  if (uri.starts_with("file://")) {
    // RFC 8089: file:///path or file://localhost/path, percent-encoded
    // (file:///a%20b.stl is 'a b.stl').
    std::string path = uri.substr(7);
    if (path.starts_with("localhost/")) path.erase(0, 9);
    std::string decoded;
    for (size_t i = 0; i < path.size(); ++i) {
      unsigned byte = 0;
      const char* hex = path.data() + i + 1;
      if (path[i] == '%' && i + 2 < path.size() &&
          std::from_chars(hex, hex + 2, byte, 16).ptr == hex + 2) {
        decoded += static_cast<char>(byte);
        i += 2;
      } else {
        decoded += path[i];
      }
    }
    return decoded;
  }
  return path_.parent_path() / uri;
}

// --- Objects ------------------------------------------------------------------------

Pose ToPose(const urdf::Pose& p) {
  return {{p.position.x, p.position.y, p.position.z},
          Quat{p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z}.Normalized()};
}

// Rotation taking z onto the unit vector `a`.
Quat ZTo(const Vec3& a) {
  const Vec3 z{0, 0, 1};
  const double c = z.Dot(a);
  if (c > 1 - 1e-12) return {};
  if (c < -1 + 1e-12) return Quat::FromAxisAngle({1, 0, 0}, M_PI);
  return Quat::FromAxisAngle(z.Cross(a), std::acos(std::clamp(c, -1.0, 1.0)));
}

// The link `joint` (one of link's child joints) leads to.
urdf::LinkConstSharedPtr ChildLink(const urdf::Link& link, const urdf::Joint& joint) {
  for (const auto& c : link.child_links)
    if (c->name == joint.child_link_name) return c;
  return nullptr;
}

ObjectSpec NewObject(ObjectType type, std::string name, const Pose& X_PO) {
  ObjectSpec spec;
  spec.type = type;
  spec.name = std::move(name);
  spec.X_PO = X_PO;
  const ObjectTypeDescriptor& descriptor = *CoreObjectTypes()[static_cast<size_t>(type)];
  if (descriptor.make_rows != nullptr) {
    spec.row = descriptor.make_rows(descriptor);
    spec.row->Append(nullptr, 0);
  }
  return spec;
}

template <typename Row>
Row& RowOf(ObjectSpec& spec) {
  return *static_cast<Row*>(spec.row->At(0));
}

// Object names are path elements: no spaces, '/', '[' or ']'.
std::string ObjectName(std::string name) {
  for (char& c : name)
    if (c == '/' || c == '[' || c == ']' || std::isspace(static_cast<unsigned char>(c))) c = '_';
  return name.empty() ? "_" : name;
}

std::optional<ObjectSpec> Importer::Geometry(const urdf::Link& link, const urdf::Geometry* g,
                                             const urdf::Pose& origin, bool visual, int line,
                                             const Vec3* color) {
  const std::string what =
      "link '" + link.name + "' " + (visual ? "<visual>" : "<collision>") + " geometry";
  if (g == nullptr) return std::nullopt;
  ObjectSpec spec = NewObject(ObjectType::kShape, visual ? "visual" : "collision", ToPose(origin));
  ShapeData& s = RowOf<Shared<ShapeData>>(spec).Edit();
  s.collidable = !visual;
  auto positive = [&](double v, const char* key) {
    if (!(v > 0) || !std::isfinite(v))
      Fail(line, what + ": " + key + " must be a positive number (got " + Num(v) + ")");
    return v;
  };
  switch (g->type) {
    case urdf::Geometry::BOX: {
      const auto& d = static_cast<const urdf::Box*>(g)->dim;
      s.kind = ShapeKind::kBox;
      s.size = {positive(d.x, "box size x"), positive(d.y, "box size y"),
                positive(d.z, "box size z")};
      break;
    }
    case urdf::Geometry::CYLINDER: {
      const auto* c = static_cast<const urdf::Cylinder*>(g);
      s.kind = ShapeKind::kCylinder;
      s.size = {positive(c->radius, "cylinder radius"), 0, positive(c->length, "cylinder length")};
      break;
    }
    case urdf::Geometry::SPHERE:
      s.kind = ShapeKind::kSphere;
      s.size = {positive(static_cast<const urdf::Sphere*>(g)->radius, "sphere radius"), 0, 0};
      break;
    case urdf::Geometry::MESH: {
      const auto* m = static_cast<const urdf::Mesh*>(g);
      const fs::path file = ResolveUri(m->filename, line, what);
      // Negative factors mirror (ROS's left and right arms from one mesh).
      auto nonzero = [&](double v, const char* key) {
        if (!(v != 0) || !std::isfinite(v))
          Fail(line, what + ": " + key + " must be a nonzero number (got " + Num(v) + ")");
        return v;
      };
      const Vec3 scale{nonzero(m->scale.x, "mesh scale x"), nonzero(m->scale.y, "mesh scale y"),
                       nonzero(m->scale.z, "mesh scale z")};
      s.kind = ShapeKind::kMesh;
      s.mesh =
          meshes_->Get(file, scale, name_ + ":" + std::to_string(line) + ": " + what, m->filename);
      s.size = s.mesh->CenteredExtents();
      std::string ext = file.extension().string();
      for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      ++mesh_formats_[ext.empty() ? "?" : ext.substr(1)];
      ++meshes_count_;
      break;
    }
    default: Fail(line, what + ": unknown geometry");
  }
  if (color != nullptr) {
    s.color = *color;
    s.mesh_colors = false;
  }
  (visual ? visuals_ : collisions_)++;
  return spec;
}

// The mass of `link` in its frame: its <inertial>, the inertia rotated from
// the <inertial> frame into the link's. A link whose inertia no rigid body
// has is repaired (BalancedInertia; all zero: a point mass, kept); no mass:
// nothing.
MassProperties Importer::LinkMass(const urdf::Link& link) {
  MassProperties part;
  if (!link.inertial || !(link.inertial->mass > 0)) return part;
  const urdf::Inertial& in = *link.inertial;
  part.mass = in.mass;
  part.inertia = {in.ixx, in.iyy, in.izz, in.ixy, in.ixz, in.iyz};
  // A diagonal of zeros is a point mass (a body's products of inertia are
  // then zero too): zeros to within the mass x 1e-12 m^2, a radius of
  // gyration under 1 um (CAD exports leave -5e-20 in the diagonal, 2e-35
  // in the products).
  const double zero = in.mass * kUrdfPointMassTolerance;
  const bool point =
      std::abs(in.ixx) <= zero && std::abs(in.iyy) <= zero && std::abs(in.izz) <= zero;
  if (point) part.inertia = {};
  if (!point && !InertiaIsPhysical(part.inertia)) {
    const auto it = xml_.inertia_line.find(link.name);
    const int line = it != xml_.inertia_line.end() ? it->second : xml_.link_line[link.name];
    if (!(in.ixx + in.iyy + in.izz > 0))
      Fail(line, "link '" + link.name +
                     "': <inertia> cannot be repaired: its principal moments sum to " +
                     Num(in.ixx + in.iyy + in.izz) + " kg m^2 (ixx " + Num(in.ixx) + ", iyy " +
                     Num(in.iyy) + ", izz " + Num(in.izz) + "); a body's are positive");
    part.inertia = BalancedInertia(part.inertia);
    repaired_links_.push_back(link.name);
  }
  const Pose X_LI = ToPose(in.origin);  // the <inertial> frame in the link
  return Transformed(part, X_LI);
}

// Adds `link` and the links fixed to it to `body`, in the frame T of the
// body's top link (X_TL: the link in T).
void Importer::GroupMass(const urdf::Link& link, const Pose& X_TL, MassProperties* body,
                         bool* has_geometry) {
  AddMass(Transformed(LinkMass(link), X_TL), body);
  if (!link.collision_array.empty() || !link.visual_array.empty()) *has_geometry = true;
  for (const urdf::JointSharedPtr& joint : ChildJoints(link))
    if (joint->type == urdf::Joint::FIXED || joint->type == urdf::Joint::PLANAR)
      if (const urdf::LinkConstSharedPtr child = ChildLink(link, *joint)) {
        ++links_merged_;
        GroupMass(*child, X_TL * ToPose(joint->parent_to_joint_origin_transform), body,
                  has_geometry);
      }
}

// The body whose top link is `top`: its links' mass combined about their
// centre of mass; the default when it can move and has none (a moving
// joint's child, or the root holding geometry: it may float); its inertia
// balanced when no rigid body has it (point masses alone).
MassProperties Importer::BodyMass(const urdf::Link& top, bool is_root) {
  MassProperties body;
  bool has_geometry = false;
  GroupMass(top, Pose{}, &body, &has_geometry);
  if (!(body.mass > 0)) {
    if (is_root && !has_geometry) return body;  // a frame, never simulated
    body.mass = kUrdfDefaultMass;
    body.center = {};
    body.inertia = {kUrdfDefaultInertia, kUrdfDefaultInertia, kUrdfDefaultInertia, 0, 0, 0};
    default_mass_links_.push_back(top.name);
    return body;
  }
  if (!InertiaIsPhysical(body.inertia)) {
    body.inertia = BalancedInertia(body.inertia);
    // Point masses alone (a mean moment under the mass's at 1e-9 m^2):
    // the default link's radius of gyration.
    const double least = body.mass * kUrdfPointMassGyration;
    std::vector<std::string>* note = &repaired_links_;
    if (!(body.inertia[0] > 1e-9 * body.mass)) {
      body.inertia = {least, least, least, 0, 0, 0};
      note = &point_mass_links_;
    }
    if (std::find(note->begin(), note->end(), top.name) == note->end()) note->push_back(top.name);
  }
  return body;
}

// Object names are unique in a robot, so that sim.getObject('./name') finds
// the one meant: joints keep their names (scripts drive them), a link named
// as a joint becomes NAME_link (ANYmal's LF_HAA link and joint), and names
// that clean to the same one (ObjectName: 'upper arm' and 'upper_arm') get
// _2, _3 in document order.
void Importer::NameObjects() {
  std::set<std::string> used;
  const auto unique = [&](std::string name) {
    if (used.contains(name))
      for (int k = 2;; ++k)
        if (!used.contains(name + "_" + std::to_string(k))) {
          name += "_" + std::to_string(k);
          break;
        }
    used.insert(name);
    return name;
  };
  const auto in_order = [](const std::map<std::string, int>& order) {
    std::vector<std::pair<int, std::string>> v;
    for (const auto& [name, k] : order) v.emplace_back(k, name);
    std::sort(v.begin(), v.end());
    return v;
  };
  std::set<std::string> joint_names;
  for (const auto& [order, joint] : in_order(xml_.joint_order)) {
    const std::string clean = ObjectName(joint);
    joint_names_[joint] = unique(clean);
    joint_names.insert(clean);
    // Against the URDF's name: 'j x' made 'j_x' was left out of the list.
    if (joint_names_[joint] != joint)
      renamed_.push_back("joint '" + joint + "' is '" + joint_names_[joint] + "'");
  }
  for (const auto& [line, link] : in_order(xml_.link_line)) {
    const std::string clean = ObjectName(link);
    link_names_[link] = unique(joint_names.contains(clean) ? clean + "_link" : clean);
    if (link_names_[link] != link)
      renamed_.push_back("link '" + link + "' is '" + link_names_[link] + "'" +
                         (joint_names.contains(clean) ? " (a joint has its name)" : ""));
  }
}

std::vector<urdf::JointSharedPtr> Importer::ChildJoints(const urdf::Link& link) const {
  std::vector<urdf::JointSharedPtr> joints = link.child_joints;
  std::sort(joints.begin(), joints.end(), [&](const auto& a, const auto& b) {
    return Named(xml_.joint_order, a->name) < Named(xml_.joint_order, b->name);
  });
  return joints;
}

// The object of `link` at X_PO in its parent: the group's body carrier
// (`top`) or a frame (a dummy), with its geometry and what hangs from it.
ObjectSpec Importer::LinkObject(const urdf::Link& link, bool top, bool is_root, const Pose& X_PO,
                                const Pose& X_TL) {
  ObjectSpec spec;
  if (top) {
    const MassProperties body = BodyMass(link, is_root);
    spec = NewObject(ObjectType::kShape, LinkName(link.name), X_PO);
    ShapeData& s = RowOf<Shared<ShapeData>>(spec).Edit();
    s.kind = ShapeKind::kSphere;
    s.size = {kUrdfCarrierRadius, 0, 0};
    s.collidable = false;
    s.visible = false;   // a mass, not a part: nothing to see
    s.mass = body.mass;  // 0: a frame, never simulated
    s.dynamic = body.mass > 0 && !is_root;
    if (body.mass > 0) {
      s.inertia = body.inertia;
      s.center_of_mass = body.center;
      ++bodies_;
      total_mass_ += body.mass;
    } else {
      ++frames_;
    }
  } else {
    spec = NewObject(ObjectType::kDummy, LinkName(link.name), X_PO);
  }
  // The link's colour (its collision shapes'): its first coloured visual's.
  const std::vector<std::optional<Vec3>>& colors = xml_.visual_colors[link.name];
  std::optional<Vec3> color;
  for (const std::optional<Vec3>& c : colors)
    if (c) {
      color = c;
      break;
    }
  const std::vector<int>& collision_lines = xml_.collision_lines[link.name];
  const std::vector<int>& visual_lines = xml_.visual_lines[link.name];
  for (size_t k = 0; k < link.collision_array.size(); ++k) {
    const auto& c = *link.collision_array[k];
    const int line = k < collision_lines.size() ? collision_lines[k] : xml_.link_line[link.name];
    if (auto shape =
            Geometry(link, c.geometry.get(), c.origin, false, line, color ? &*color : nullptr)) {
      // Drawn only when the link has nothing else to show: the visuals are
      // what the robot looks like, the collision geometry what it touches.
      if (!link.visual_array.empty()) RowOf<Shared<ShapeData>>(*shape).Edit().visible = false;
      spec.children.push_back(std::move(*shape));
    }
  }
  for (size_t k = 0; k < link.visual_array.size(); ++k) {
    const auto& v = *link.visual_array[k];
    const int line = k < visual_lines.size() ? visual_lines[k] : xml_.link_line[link.name];
    const std::optional<Vec3> own = k < colors.size() ? colors[k] : std::nullopt;
    if (auto shape = Geometry(link, v.geometry.get(), v.origin, true, line, own ? &*own : nullptr))
      spec.children.push_back(std::move(*shape));
  }
  for (const urdf::JointSharedPtr& joint : ChildJoints(link)) {
    const urdf::LinkConstSharedPtr child = ChildLink(link, *joint);
    if (!child) continue;
    const int line = xml_.joint_line[joint->name];
    const Pose X_LJ = ToPose(joint->parent_to_joint_origin_transform);
    switch (joint->type) {
      case urdf::Joint::FIXED:
      case urdf::Joint::PLANAR:
        ++joint_kinds_[joint->type == urdf::Joint::FIXED ? "fixed" : "planar (as fixed)"];
        merged_joints_[joint_names_[joint->name]] =
            joint->type == urdf::Joint::FIXED ? "fixed" : "planar (imported as fixed)";
        spec.children.push_back(LinkObject(*child, false, false, X_LJ, X_TL * X_LJ));
        continue;
      case urdf::Joint::FLOATING:
        // A free body: no joint between it and its parent.
        ++joint_kinds_["floating"];
        merged_joints_[joint_names_[joint->name]] = "floating";
        spec.children.push_back(LinkObject(*child, true, false, X_LJ, Pose{}));
        continue;
      default: break;
    }
    Vec3 axis{joint->axis.x, joint->axis.y, joint->axis.z};
    // Scaled by its largest component first: "0 1e300 1e300" is a direction
    // (its norm overflowed, and it was called zero).
    const double largest = std::max({std::abs(axis.x), std::abs(axis.y), std::abs(axis.z)});
    if (!std::isfinite(largest))
      Fail(line, "joint '" + joint->name + "': <axis xyz> must be finite");
    if (!(largest > 0) || !((axis / largest).Norm() * largest > 1e-9))
      Fail(line, "joint '" + joint->name + "': <axis xyz> must be a nonzero vector");
    axis = (axis / largest).Normalized();
    const Quat z_to_axis = ZTo(axis);
    ObjectSpec j =
        NewObject(ObjectType::kJoint, JointName(joint->name), X_LJ * Pose{{}, z_to_axis});
    JointData& d = RowOf<JointData>(j);
    JointSettings& settings = d.settings.Edit();  // this entry's, shared by its copies
    settings.type =
        joint->type == urdf::Joint::PRISMATIC ? JointType::kPrismatic : JointType::kRevolute;
    settings.mode =
        joint->type == urdf::Joint::CONTINUOUS ? JointMode::kVelocity : JointMode::kPosition;
    ++joint_kinds_[joint->type == urdf::Joint::CONTINUOUS  ? "continuous"
                   : joint->type == urdf::Joint::PRISMATIC ? "prismatic"
                                                           : "revolute"];
    if (joint->limits) {
      if (joint->type != urdf::Joint::CONTINUOUS) {
        if (!(joint->limits->lower <= joint->limits->upper))
          Fail(line, "joint '" + joint->name + "': <limit lower> is above upper");
        settings.min_position = joint->limits->lower;
        settings.max_position = joint->limits->upper;
        if (joint->limits->lower == joint->limits->upper) held_joints_.push_back(joint->name);
        // Start inside the limits.
        d.position = d.target_position =
            std::clamp(0.0, settings.min_position, settings.max_position);
      }
      if (joint->limits->effort > 0)
        settings.max_force = joint->limits->effort;
      else
        settings.max_force = kUrdfDefaultEffort;
      settings.max_velocity =
          joint->limits->velocity > 0 ? joint->limits->velocity : kUrdfDefaultVelocity;
    } else {
      settings.max_force = kUrdfDefaultEffort;
      settings.max_velocity = kUrdfDefaultVelocity;
    }
    if (joint->dynamics) settings.damping = joint->dynamics->damping;
    if (joint->mimic) {
      auto dep = std::make_shared<JointDependency>();
      dep->master = ":/" + JointName(joint->mimic->joint_name);
      dep->factor = joint->mimic->multiplier;
      dep->offset = joint->mimic->offset;
      dep->where = name_ + ":" + std::to_string(xml_.mimic_line[joint->name]);
      settings.depends = std::move(dep);
      settings.mode = JointMode::kPosition;
      ++mimics_;
    }
    j.children.push_back(LinkObject(*child, true, false, Pose{{}, z_to_axis.Conjugate()}, Pose{}));
    spec.children.push_back(std::move(j));
  }
  return spec;
}

UrdfImport Importer::Run(const std::string& where, const std::string& text) {
  const std::string bytes = ReadFileOrThrow(path_, "URDF file", where, text);
  xml_ = ReadUrdfXml(bytes, name_);
  urdf::ModelInterfaceSharedPtr model;
  {
    // urdfdom reports through console_bridge's process-wide handler, and
    // passes some of its messages, the file's text inside, as printf
    // formats: a '%' in the file would be read as a conversion (a crash).
    // So a file holding '%' is parsed with no handler (console_bridge then
    // formats nothing), and on failure its message comes from a copy with
    // '?' for each '%'.
    static std::mutex mutex;
    std::lock_guard lock(mutex);
    const auto parse = [](const std::string& xml, std::string* message) {
      Capture capture;
      if (message != nullptr)
        console_bridge::useOutputHandler(&capture);
      else
        console_bridge::noOutputHandler();
      urdf::ModelInterfaceSharedPtr parsed;
      try {
        parsed = urdf::parseURDF(xml);
      } catch (const std::exception& e) {
        capture.first_error = e.what();
      }
      console_bridge::restorePreviousOutputHandler();
      if (message != nullptr) *message = capture.first_error;
      return parsed;
    };
    std::string message;
    if (bytes.find('%') == std::string::npos) {
      model = parse(bytes, &message);
    } else if (!(model = parse(bytes, nullptr))) {
      std::string quiet = bytes;
      std::replace(quiet.begin(), quiet.end(), '%', '?');
      parse(quiet, &message);
    }
    if (!model) {
      // Bytes that are not UTF-8 (a name cut inside a character): urdfdom
      // says "Error reading Attributes." with no line; the line is found
      // here (a newline is never inside a UTF-8 sequence).
      int line = 1;
      for (size_t start = 0; start < bytes.size(); ++line) {
        const size_t end = std::min(bytes.find('\n', start), bytes.size());
        if (!IsValidUtf8(std::string_view(bytes).substr(start, end - start)))
          Fail(line, "this line is not valid UTF-8, and urdfdom cannot read the file (" +
                         (message.empty() ? std::string("no message") : message) +
                         "): save it as UTF-8");
        start = end + 1;
      }
      Fail(0,
           "urdfdom cannot read it: " + (message.empty() ? std::string("(no message)") : message));
    }
  }
  if (!model->getRoot()) Fail(0, "the robot has no root link");
  UrdfImport out;
  out.name = ObjectName(model->getName());
  for (char& c : out.name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') c = '_';
  NameObjects();
  out.root = LinkObject(*model->getRoot(), true, true, Pose{}, Pose{});
  out.merged_joints = std::move(merged_joints_);

  std::string joints;
  for (const auto& [kind, n] : joint_kinds_)
    joints += (joints.empty() ? "" : ", ") + std::to_string(n) + " " + kind;
  std::string formats;
  for (const auto& [ext, n] : mesh_formats_)
    formats += (formats.empty() ? "" : ", ") + std::to_string(n) + " " + ext;
  int joint_count = 0;
  for (const auto& [kind, n] : joint_kinds_) joint_count += n;
  out.summary.push_back("urdf: robot '" + model->getName() + "', root link '" +
                        model->getRoot()->name + "'");
  out.summary.push_back(
      "  links: " + std::to_string(xml_.link_line.size()) + ", " + std::to_string(links_merged_) +
      " merged by fixed joints into " + std::to_string(bodies_) + " bodies with mass (" +
      Num(total_mass_) + " kg in all; " + std::to_string(default_mass_links_.size()) +
      " with the default mass, " + std::to_string(repaired_links_.size()) + " inertias repaired)");
  out.summary.push_back("  joints: " + std::to_string(joint_count) +
                        (joints.empty() ? "" : " (" + joints + ")") +
                        (mimics_ ? ", " + std::to_string(mimics_) + " mimic (dependent)" : ""));
  out.summary.push_back("  shapes: " + std::to_string(collisions_) + " collision, " +
                        std::to_string(visuals_) +
                        " visual; meshes: " + std::to_string(meshes_count_) +
                        (formats.empty() ? "" : " (" + formats + ")"));
  for (const auto& [kind, count_line] : xml_.ignored)
    out.warnings.push_back(name_ + ":" + std::to_string(count_line.second) + ": ignored " +
                           std::to_string(count_line.first) + " " + kind +
                           (count_line.first == 1 ? "" : " (first here)"));
  auto list = [](const std::vector<std::string>& names) {
    std::string out;
    for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
    return out;
  };
  const auto plural = [](size_t n, const char* one, const char* many) {
    return std::to_string(n) + " " + (n == 1 ? one : many);
  };
  if (!repaired_links_.empty())
    out.warnings.push_back(
        name_ + ": the inertia of " + plural(repaired_links_.size(), "link", "links") + " (" +
        list(repaired_links_) +
        ") is no rigid body's (not positive definite, or a principal moment above the sum of "
        "the other two): balanced as MuJoCo's balanceinertia does, each principal moment "
        "replaced by their mean");
  if (!point_mass_links_.empty())
    out.warnings.push_back(
        name_ + ": " + plural(point_mass_links_.size(), "body is", "bodies are") +
        " point masses only, with no inertia (" + list(point_mass_links_) +
        "): each gets its mass x " + Num(kUrdfPointMassGyration) + " m^2 about each axis");
  if (!held_joints_.empty())
    out.warnings.push_back(
        name_ + ": " + plural(held_joints_.size(), "joint has", "joints have") +
        " <limit lower> equal to upper (" + list(held_joints_) +
        "): held there as by a fixed joint; a models entry's joints: {limits: false} frees "
        "them, joints: {mode: passive} lets them swing");
  if (!renamed_.empty())
    out.warnings.push_back(name_ + ": " + plural(renamed_.size(), "name was", "names were") +
                           " changed so that scripts find each object by its name (" +
                           list(renamed_) + ")");
  if (!default_mass_links_.empty())
    out.warnings.push_back(
        name_ + ": " + plural(default_mass_links_.size(), "link", "links") +
        " that can move (a moving joint's child, or the root with geometry) " +
        (default_mass_links_.size() == 1 ? "has" : "have") + " no mass, nor links fixed to " +
        (default_mass_links_.size() == 1 ? "it" : "them") + " (" + list(default_mass_links_) +
        "): each gets the default mass " + Num(kUrdfDefaultMass) + " kg and inertia " +
        Num(kUrdfDefaultInertia) + " kg m^2 about each axis at the link origin");
  return out;
}

}  // namespace

bool IsUrdfFile(const std::string& text) {
  if (text.size() < 5) return false;
  std::string ext = text.substr(text.size() - 5);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".urdf";
}

UrdfImport ImportUrdf(const fs::path& path, const std::string& where, const std::string& text,
                      const std::vector<fs::path>& package_path, MeshCache* meshes) {
  MeshCache own;
  return Importer(path, package_path, meshes ? meshes : &own).Run(where, text);
}

ObjectSpec WithFloatingBase(const ObjectSpec& root, const std::string& where) {
  ObjectSpec out = root;
  const ShapeData* shape = root.AsShape();
  if (shape == nullptr || shape->dynamic) return out;
  if (!(shape->mass > 0))
    throw Error(where +
                ": 'base: floating' needs a root link with mass (the root link and the "
                "links fixed to it have no <inertial> nor geometry)");
  const ObjectTypeDescriptor& type = *CoreObjectTypes()[static_cast<size_t>(ObjectType::kShape)];
  out.row = type.make_rows(type);
  const Shared<ShapeData> row(*shape);
  out.row->Append(&row, 0);
  static_cast<Shared<ShapeData>*>(out.row->At(0))->Edit().dynamic = true;
  return out;
}

}  // namespace swarmsim::loader
