// ObjectReader's optional parts: a reader that does not read nested values
// (a test's fake) refuses them; the names of visual kinds (visual.h).
#include "framework/object_type.h"

#include "framework/error.h"

namespace swarmsim {

namespace {
[[noreturn]] void Unsupported(const char* what) {
  throw Error(std::string("this reader does not read ") + what);
}
}  // namespace

void ObjectReader::Require(std::string_view) const { Unsupported("required keys"); }

std::unique_ptr<ObjectReader> ObjectReader::Map(std::string_view, const std::string&,
                                                std::string_view) const {
  Unsupported("nested mappings");
}

std::vector<std::unique_ptr<ObjectReader>> ObjectReader::Elements(std::string_view,
                                                                  std::string_view,
                                                                  const std::string&,
                                                                  std::string_view) const {
  Unsupported("lists of values");
}

void ObjectReader::FailHere(const std::string& message) const { throw Error(message); }

std::vector<std::unique_ptr<ObjectReader>> ObjectReader::Maps(std::string_view, std::string_view,
                                                              const std::string&) const {
  Unsupported("lists of maps");
}
bool ObjectReader::IsList(std::string_view) const { Unsupported("lists"); }
std::vector<std::string> ObjectReader::Keys() const { Unsupported("keys as names"); }
std::string ObjectReader::WhereKey(std::string_view) const { return {}; }
std::string ObjectReader::WhereHere() const { return {}; }

const char* ToString(VisualKind kind) {
  switch (kind) {
    case VisualKind::kNone: return "none";
    case VisualKind::kBox: return "box";
    case VisualKind::kCylinder: return "cylinder";
    case VisualKind::kSphere: return "sphere";
    case VisualKind::kCapsule: return "capsule";
    case VisualKind::kMesh: return "mesh";
    case VisualKind::kLight: return "light";
    case VisualKind::kRay: return "ray";
  }
  return "none";
}

}  // namespace swarmsim
