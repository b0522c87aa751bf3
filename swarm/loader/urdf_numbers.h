// Every attribute urdfdom reads a number from, checked first (urdf.cc), so
// that a number urdfdom cannot read, reads as NaN or silently skips
// (<mass value="abc"> gave a massless link) is an error naming the line and
// the attribute. tinyxml2 is the loader's own XML reader for URDF files.
#pragma once

#include <optional>
#include <string>

namespace tinyxml2 {
class XMLElement;
}

namespace swarmsim::loader {

struct BadNumber {
  int line = 0;
  std::string message;  // "link 'a' <inertial>: <mass value=\"abc\">: 'abc' is not a finite number"
};

// The first numeric attribute of a <link>, <joint> or top-level <material>
// (its own elements urdfdom reads) that does not hold its count of finite
// numbers; nullopt when all do.
std::optional<BadNumber> FindBadNumber(const tinyxml2::XMLElement* top);

}  // namespace swarmsim::loader
