// The XML pass of a URDF import (urdf.cc): the lines of its links, joints,
// visuals, collisions, inertias and mimics for messages, the checks urdfdom
// does not make (names defined twice, joints naming missing links, loops,
// several roots, bad numbers), each visual's colour, and the elements the
// import ignores, read with tinyxml2 before urdfdom parses the text.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "framework/math.h"

namespace swarmsim::loader {

struct UrdfXmlFacts {
  std::map<std::string, int> link_line, joint_line, mimic_line;
  std::map<std::string, std::vector<int>> visual_lines, collision_lines;  // per link, in order
  std::map<std::string, int> inertia_line;  // per link with an <inertia>
  // Each visual's colour, per link in order (its material's <color rgba>,
  // inline or the named material's); none: no colour (alpha 0 included).
  std::map<std::string, std::vector<std::optional<Vec3>>> visual_colors;
  std::map<std::string, int> joint_order;  // document order of each joint
  // Ignored elements, by kind: count and first line.
  std::map<std::string, std::pair<int, int>> ignored;
};

// The facts of `bytes`, a URDF's text. Throws Error "NAME:LINE: ..." (name:
// the file as messages show it) for malformed XML, a DTD, a root that is not
// <robot>, and the structural mistakes above.
UrdfXmlFacts ReadUrdfXml(const std::string& bytes, const std::string& name);

}  // namespace swarmsim::loader
