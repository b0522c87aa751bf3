#include "swarm/loader/urdf_xml.h"

#include <tinyxml2.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <tuple>

#include "framework/error.h"
#include "framework/number_rule.h"
#include "framework/suggest.h"
#include "swarm/loader/check_text.h"
#include "swarm/loader/urdf_numbers.h"

namespace swarmsim::loader {
namespace {

std::string Num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}

class XmlReader {
 public:
  explicit XmlReader(const std::string& name) : name_(name) {}
  UrdfXmlFacts Read(const std::string& bytes);

 private:
  [[noreturn]] void Fail(int line, const std::string& message) const {
    throw Error(name_ + (line > 0 ? ":" + std::to_string(line) : "") + ": " + message);
  }
  void Ignore(const std::string& kind, int line) {
    auto [it, added] = facts_.ignored.emplace(kind, std::make_pair(0, line));
    ++it->second.first;
  }
  const std::string& name_;
  UrdfXmlFacts facts_;
};

UrdfXmlFacts XmlReader::Read(const std::string& bytes) {
  CheckXmlHasNoDtd(bytes, name_, "URDF");
  tinyxml2::XMLDocument doc;
  if (doc.Parse(bytes.data(), bytes.size()) != tinyxml2::XML_SUCCESS) {
    // Tags that do not nest: named at the tag that broke them (tinyxml2
    // names the element it was in: <robot> for a misspelt </robt>).
    int line = 0;
    if (const std::string nesting = XmlNestingProblem(bytes, &line); !nesting.empty())
      Fail(line, "malformed XML: " + nesting);
    Fail(doc.ErrorLineNum(),
         "malformed XML: " + XmlParseErrorInWords(doc.ErrorID(), doc.ErrorStr()));
  }
  // What tinyxml2 lets pass: a stray closing tag after the root's end, a
  // second top-level element.
  int nesting_line = 0;
  if (const std::string nesting = XmlNestingProblem(bytes, &nesting_line); !nesting.empty())
    Fail(nesting_line, "malformed XML: " + nesting);
  const tinyxml2::XMLElement* robot = doc.RootElement();
  if (!robot || std::string(robot->Name()) != "robot")
    Fail(robot ? robot->GetLineNum() : 1, "a URDF file's root element must be <robot>");
  if (const tinyxml2::XMLElement* more = robot->NextSiblingElement())
    Fail(more->GetLineNum(), std::string("<") + more->Name() +
                                 "> after </robot>: a URDF file holds one <robot> element");
  if (!robot->Attribute("name")) Fail(robot->GetLineNum(), "<robot> needs a 'name' attribute");
  // A xacro file not expanded: its macros' robot parts were left out in
  // silence (ignored elements), its ${...} names kept as names.
  std::function<void(const tinyxml2::XMLElement*)> no_xacro = [&](const tinyxml2::XMLElement* e) {
    constexpr const char* kExpand =
        ": this is a xacro file, not yet URDF: expand it first (xacro robot.urdf.xacro > "
        "robot.urdf) and name the .urdf";
    // Appended, not "<" + ...: GCC 12 warns (-Wrestrict, a false positive) on that form.
    std::string tag = "<";
    tag += e->Name();
    if (std::string_view(e->Name()).starts_with("xacro:"))
      Fail(e->GetLineNum(), tag + ">" + kExpand);
    for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a; a = a->Next()) {
      const std::string_view value = a->Value();
      if (value.find("${") == std::string_view::npos && value.find("$(") == std::string_view::npos)
        continue;
      tag += ' ';
      tag += a->Name();
      tag += "=\"";
      tag += value;
      tag += "\">";
      Fail(e->GetLineNum(), tag + kExpand);
    }
    for (const tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement())
      no_xacro(c);
  };
  no_xacro(robot);
  std::map<std::string, std::string> parent_joint;                // child link -> joint
  std::map<std::string, std::string> parent_link;                 // child link -> parent link
  std::vector<std::tuple<std::string, std::string, int>> mimics;  // joint, master, line
  std::map<std::string, std::string> joint_type;                  // joint -> its type
  // Each visual's <material> (or null), per link in order, resolved below.
  std::vector<std::pair<std::string, const tinyxml2::XMLElement*>> visual_materials;
  int order = 0;
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement(); e; e = e->NextSiblingElement()) {
    const std::string kind = e->Name();
    const int line = e->GetLineNum();
    if (kind == "link" || kind == "joint" || kind == "material")
      if (const std::optional<BadNumber> bad = FindBadNumber(e)) Fail(bad->line, bad->message);
    if (kind == "link") {
      const char* name = e->Attribute("name");
      if (!name || !*name) Fail(line, "<link> needs a 'name' attribute");
      if (!facts_.link_line.emplace(name, line).second)
        Fail(line, "link '" + std::string(name) + "' is defined twice (first at line " +
                       std::to_string(facts_.link_line[name]) + ")");
      for (const tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
        const std::string part = c->Name();
        if (part == "visual" || part == "collision") {
          auto& lines = part == "visual" ? facts_.visual_lines[name] : facts_.collision_lines[name];
          const tinyxml2::XMLElement* g = c->FirstChildElement("geometry");
          const tinyxml2::XMLElement* shape = g ? g->FirstChildElement() : nullptr;
          const std::string what = "link '" + std::string(name) + "' <" + part + ">";
          if (!shape)
            Fail(c->GetLineNum(),
                 what + " needs <geometry> holding a box, cylinder, sphere or mesh");
          const std::string kind = shape->Name();
          if (kind != "box" && kind != "cylinder" && kind != "sphere" && kind != "mesh")
            Fail(shape->GetLineNum(),
                 what + ": unknown geometry <" + kind + "> (box, cylinder, sphere or mesh)");
          if (kind == "mesh" && !shape->Attribute("filename"))
            Fail(shape->GetLineNum(), what + ": <mesh> needs a 'filename'");
          lines.push_back(g && g->FirstChildElement() ? g->FirstChildElement()->GetLineNum()
                                                      : c->GetLineNum());
          if (const tinyxml2::XMLElement* m = c->FirstChildElement("material"))
            if (m->FirstChildElement("texture")) Ignore("<texture> (materials' textures)", line);
          if (part == "visual")
            visual_materials.emplace_back(name, c->FirstChildElement("material"));
        } else if (part == "inertial") {
          double mass = 0;
          const tinyxml2::XMLElement* m = c->FirstChildElement("mass");
          if (m && m->QueryDoubleAttribute("value", &mass) == tinyxml2::XML_SUCCESS &&
              !(mass >= 0 && mass <= kMaxMass))
            Fail(m->GetLineNum(), "link '" + std::string(name) + "': <mass value=\"" + Num(mass) +
                                      "\"> must be a non-negative number of kg, at most 1e9");
          if (const tinyxml2::XMLElement* in = c->FirstChildElement("inertia")) {
            facts_.inertia_line[name] = in->GetLineNum();
            // 1e9 kg spread over 30 m: past that the solvers' arithmetic breaks.
            for (const char* key : {"ixx", "iyy", "izz", "ixy", "ixz", "iyz"}) {
              double v = 0;
              if (in->QueryDoubleAttribute(key, &v) == tinyxml2::XML_SUCCESS &&
                  !(std::abs(v) <= 1e12))
                Fail(in->GetLineNum(), "link '" + std::string(name) + "': <inertia " + key + "=\"" +
                                           Num(v) + "\"> is past 1e12 kg m^2");
            }
          }
        } else {
          Ignore("<" + part + "> in a link", c->GetLineNum());
        }
      }
    } else if (kind == "joint") {
      const char* name = e->Attribute("name");
      if (!name || !*name) Fail(line, "<joint> needs a 'name' attribute");
      if (!facts_.joint_line.emplace(name, line).second)
        Fail(line, "joint '" + std::string(name) + "' is defined twice (first at line " +
                       std::to_string(facts_.joint_line[name]) + ")");
      facts_.joint_order[name] = order++;
      const std::string type = e->Attribute("type") ? e->Attribute("type") : "";
      joint_type[name] = type;
      if (type != "revolute" && type != "continuous" && type != "prismatic" && type != "fixed" &&
          type != "floating" && type != "planar")
        Fail(line, "joint '" + std::string(name) + "': unknown type '" + type +
                       "' (revolute, continuous, prismatic, fixed, floating or planar)");
      if ((type == "revolute" || type == "prismatic") && !e->FirstChildElement("limit"))
        Fail(line, "joint '" + std::string(name) + "' is " + type +
                       " and needs <limit lower upper effort velocity>");
      const tinyxml2::XMLElement* p = e->FirstChildElement("parent");
      const tinyxml2::XMLElement* c = e->FirstChildElement("child");
      const char* parent = p ? p->Attribute("link") : nullptr;
      const char* child = c ? c->Attribute("link") : nullptr;
      if (!parent)
        Fail(p ? p->GetLineNum() : line,
             "joint '" + std::string(name) + "' needs <parent link=\"...\"/>");
      if (!child)
        Fail(c ? c->GetLineNum() : line,
             "joint '" + std::string(name) + "' needs <child link=\"...\"/>");
      if (auto [it, added] = parent_joint.emplace(child, name); !added)
        Fail(c->GetLineNum(), "link '" + std::string(child) + "' is the child of two joints, '" +
                                  it->second + "' (line " +
                                  std::to_string(facts_.joint_line[it->second]) + ") and '" + name +
                                  "': the kinematic tree has a loop");
      parent_link[child] = parent;
      if (const tinyxml2::XMLElement* m = e->FirstChildElement("mimic")) {
        facts_.mimic_line[name] = m->GetLineNum();
        mimics.emplace_back(name, m->Attribute("joint") ? m->Attribute("joint") : "",
                            m->GetLineNum());
      }
      for (const tinyxml2::XMLElement* k = e->FirstChildElement(); k; k = k->NextSiblingElement()) {
        const std::string part = k->Name();
        if (part == "safety_controller" || part == "calibration")
          Ignore("<" + part + "> in a joint", k->GetLineNum());
        if (part == "dynamics") {
          double damping = 0, friction = 0;
          k->QueryDoubleAttribute("damping", &damping);
          k->QueryDoubleAttribute("friction", &friction);
          if (!(damping >= 0 && damping <= 1e12))
            Fail(k->GetLineNum(), "joint '" + std::string(name) + "': <dynamics damping=\"" +
                                      Num(damping) +
                                      "\"> must be a non-negative number, at most 1e12");
          if (friction != 0) Ignore("joint <dynamics> friction (not simulated)", k->GetLineNum());
        }
      }
    } else if (kind != "material") {
      Ignore("<" + kind + ">", line);
    }
  }
  // Every joint names links the file defines; one root; no loops.
  for (const auto& [child, joint] : parent_joint) {
    const int line = facts_.joint_line[joint];
    if (!facts_.link_line.contains(child))
      Fail(line, "joint '" + joint + "' names child link '" + child +
                     "', which the file does not define");
    const std::string& parent = parent_link[child];
    if (!facts_.link_line.contains(parent))
      Fail(line, "joint '" + joint + "' names parent link '" + parent +
                     "', which the file does not define");
    if (parent == child) Fail(line, "joint '" + joint + "' joins link '" + child + "' to itself");
  }
  if (facts_.link_line.empty()) Fail(robot->GetLineNum(), "the robot has no <link>");
  std::vector<std::string> roots;
  for (const auto& [link, line] : facts_.link_line)
    if (!parent_joint.contains(link)) roots.push_back(link);
  // Links that do not reach a root through their parents are on a loop.
  for (const auto& [link, line] : facts_.link_line) {
    std::string at = link;
    for (size_t steps = 0; parent_link.contains(at); ++steps) {
      at = parent_link[at];
      if (steps > facts_.link_line.size()) {
        const std::string& joint = parent_joint[link];
        Fail(facts_.joint_line[joint],
             "the kinematic tree has a loop through link '" + link + "' (joint '" + joint + "')");
      }
    }
  }
  if (roots.size() > 1)
    Fail(facts_.link_line[roots[1]], "the robot has several root links ('" + roots[0] + "', '" +
                                         roots[1] +
                                         "'): every link but one must be a joint's child");
  for (const auto& [joint, master, line] : mimics) {
    if (!facts_.joint_line.contains(master)) {
      std::vector<std::string> moving;
      for (const auto& [other, type] : joint_type)
        if (other != joint && type != "fixed" && type != "floating") moving.push_back(other);
      Fail(line, "joint '" + joint + "': <mimic joint=\"" + master +
                     "\"> names a joint the file does not define" + Suggest(master, moving));
    }
    if (master == joint) Fail(line, "joint '" + joint + "': <mimic> names the joint itself");
    const std::string& type = joint_type[master];
    if (type == "fixed" || type == "floating")
      Fail(line, "joint '" + joint + "': <mimic joint=\"" + master + "\">: '" + master + "' is a " +
                     type +
                     " joint, which has no position to follow (name a revolute, continuous or "
                     "prismatic joint)");
  }
  // Colours: a visual's own <color rgba>, else its named material's, a
  // robot-level <material> (the first of a name) or one a visual defined
  // with a colour (urdfdom's rule). rgba's alpha is not imported (0: none).
  auto rgb = [](const tinyxml2::XMLElement* material) -> std::optional<std::optional<Vec3>> {
    const tinyxml2::XMLElement* color = material ? material->FirstChildElement("color") : nullptr;
    const char* rgba = color ? color->Attribute("rgba") : nullptr;
    if (rgba == nullptr) return std::nullopt;  // no colour of its own
    double v[4] = {0, 0, 0, 1};
    char* end = const_cast<char*>(rgba);
    for (double& x : v) x = std::strtod(end, &end);  // four finite numbers (FindBadNumber)
    if (!(v[3] > 0)) return std::optional<Vec3>();
    return std::optional<Vec3>(
        Vec3{std::clamp(v[0], 0.0, 1.0), std::clamp(v[1], 0.0, 1.0), std::clamp(v[2], 0.0, 1.0)});
  };
  std::map<std::string, std::optional<Vec3>> named;
  for (const tinyxml2::XMLElement* m = robot->FirstChildElement("material"); m;
       m = m->NextSiblingElement("material"))
    if (const char* name = m->Attribute("name"))
      if (auto color = rgb(m)) named.emplace(name, *color);
  for (const auto& [link, material] : visual_materials)
    if (const char* name = material ? material->Attribute("name") : nullptr)
      if (auto color = rgb(material)) named.emplace(name, *color);
  for (const auto& [link, material] : visual_materials) {
    std::optional<Vec3> color;
    if (auto own = rgb(material)) {
      color = *own;
    } else if (const char* name = material ? material->Attribute("name") : nullptr) {
      if (auto it = named.find(name); it != named.end()) color = it->second;
    }
    facts_.visual_colors[link].push_back(color);
  }
  return std::move(facts_);
}

}  // namespace

UrdfXmlFacts ReadUrdfXml(const std::string& bytes, const std::string& name) {
  return XmlReader(name).Read(bytes);
}

}  // namespace swarmsim::loader
