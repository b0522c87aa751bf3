// The numbers of a URDF file, checked before urdfdom reads them (urdf.cc).
#include "swarm/loader/urdf_numbers.h"

#include <tinyxml2.h>

#include <algorithm>
#include <string_view>
#include <utility>
#include <vector>

#include "framework/math.h"
#include "swarm/loader/check_text.h"

namespace swarmsim::loader {

namespace {

// The numeric attributes of the elements urdfdom reads, and how many
// numbers each holds.
struct NumericAttribute {
  const char* element;
  const char* attribute;
  int count;
  // Each number's bounds, and what they are in words (null: any finite number).
  double min = -1e308, max = 1e308;
  const char* rule = nullptr;
};
// Lengths within what a world may use (framework/math.h's kMaxCoordinate:
// a world file, a script, a mesh are held to it too).
constexpr const char* kCoordinateRule = "a coordinate from -1e6 to 1e6 m";
constexpr const char* kSizeRule = "a size from 0 to 1e6 m";
constexpr NumericAttribute kNumericAttributes[] = {
    {"origin", "xyz", 3, -kMaxCoordinate, kMaxCoordinate, kCoordinateRule},
    {"origin", "rpy", 3},
    {"mass", "value", 1},
    {"inertia", "ixx", 1},
    {"inertia", "ixy", 1},
    {"inertia", "ixz", 1},
    {"inertia", "iyy", 1},
    {"inertia", "iyz", 1},
    {"inertia", "izz", 1},
    {"box", "size", 3, 0, kMaxCoordinate, kSizeRule},
    {"cylinder", "radius", 1, 0, kMaxCoordinate, kSizeRule},
    {"cylinder", "length", 1, 0, kMaxCoordinate, kSizeRule},
    {"sphere", "radius", 1, 0, kMaxCoordinate, kSizeRule},
    {"mesh", "scale", 3},
    {"color", "rgba", 4},
    {"axis", "xyz", 3},
    {"limit", "lower", 1},
    {"limit", "upper", 1},
    {"limit", "effort", 1, 0, 1e308, "0 or more (N or N m)"},
    {"limit", "velocity", 1, 0, 1e308, "0 or more (m/s or rad/s)"},
    {"dynamics", "damping", 1},
    {"dynamics", "friction", 1},
    {"mimic", "multiplier", 1},
    {"mimic", "offset", 1},
    {"safety_controller", "soft_lower_limit", 1},
    {"safety_controller", "soft_upper_limit", 1},
    {"safety_controller", "k_position", 1},
    {"safety_controller", "k_velocity", 1},
    {"calibration", "rising", 1},
    {"calibration", "falling", 1},
    {"calibration", "reference_position", 1},
};

// Each numeric attribute of `e` holds its count of finite numbers; the
// first that does not, naming the attribute. `owner`: "link 'x'".
std::optional<BadNumber> CheckNumbers(const tinyxml2::XMLElement* e, const std::string& owner) {
  if (e == nullptr) return std::nullopt;
  const std::string_view element = e->Name();
  for (const NumericAttribute& a : kNumericAttributes) {
    if (element != a.element) continue;
    const char* value = e->Attribute(a.attribute);
    if (value == nullptr) continue;
    std::string shown(value);
    if (shown.size() > 60) shown = shown.substr(0, 60) + "...";
    for (char& c : shown)
      if (static_cast<unsigned char>(c) < 0x20) c = ' ';
    const std::string what =
        owner + ": <" + std::string(element) + " " + a.attribute + "=\"" + shown + "\">";
    int found = 0;
    std::optional<BadNumber> bad;
    ForEachToken(value, [&](std::string_view token) {
      double number;
      if (!ParseFinite(token, &number)) {
        bad = BadNumber{e->GetLineNum(), what + ": " + Quoted(token) + " is not a finite number"};
        return false;
      }
      if (a.rule != nullptr && (number < a.min || number > a.max)) {
        bad = BadNumber{e->GetLineNum(), what + ": " + Quoted(token) + " is not " + a.rule};
        return false;
      }
      ++found;
      return true;
    });
    if (bad) return bad;
    if (found != a.count)
      return BadNumber{e->GetLineNum(),
                       what + " needs " +
                           (a.count == 1 ? "a number" : std::to_string(a.count) + " numbers") +
                           (found == 0 ? "" : " (it has " + std::to_string(found) + ")")};
  }
  return std::nullopt;
}

}  // namespace

std::optional<BadNumber> FindBadNumber(const tinyxml2::XMLElement* top) {
  const std::string kind = top->Name();
  const std::string owner =
      kind + " '" + (top->Attribute("name") ? top->Attribute("name") : "") + "'";
  // The elements urdfdom reads numbers from, each with its owner's words.
  std::vector<std::pair<const tinyxml2::XMLElement*, std::string>> parts;
  if (kind == "material") {
    parts.emplace_back(top->FirstChildElement("color"), owner);
  } else if (kind == "joint") {
    for (const char* part :
         {"origin", "axis", "limit", "dynamics", "mimic", "safety_controller", "calibration"})
      parts.emplace_back(top->FirstChildElement(part), owner);
  } else {
    if (const tinyxml2::XMLElement* inertial = top->FirstChildElement("inertial"))
      for (const char* part : {"origin", "mass", "inertia"})
        parts.emplace_back(inertial->FirstChildElement(part), owner + " <inertial>");
    for (const char* part : {"visual", "collision"})
      for (const tinyxml2::XMLElement* v = top->FirstChildElement(part); v;
           v = v->NextSiblingElement(part)) {
        const std::string where = owner + " <" + part + ">";
        parts.emplace_back(v->FirstChildElement("origin"), where);
        if (const tinyxml2::XMLElement* g = v->FirstChildElement("geometry"))
          parts.emplace_back(g->FirstChildElement(), where);
        if (const tinyxml2::XMLElement* m = v->FirstChildElement("material"))
          parts.emplace_back(m->FirstChildElement("color"), where);
      }
  }
  for (const auto& [element, where] : parts)
    if (std::optional<BadNumber> bad = CheckNumbers(element, where)) return bad;
  return std::nullopt;
}

}  // namespace swarmsim::loader
