// The text form of a graph's streams: "[NAME =] KIND [PATH] [COMPONENT]".
#include <array>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/suggest.h"
#include "modules/graphs/rows.h"

namespace swarmsim::graphs {

namespace {

// What each kind takes: an object path, and which components (the first
// three are what a vector without a component expands to).
struct KindInfo {
  const char* name;
  StreamKind kind;
  bool vector;  // x, y, z (and norm), or roll, pitch, yaw
  bool angles;  // roll, pitch, yaw
  const char* unit;
  const char* example;
};

constexpr KindInfo kKinds[] = {
    {"position", StreamKind::kPosition, true, false, "m", "position :/body x"},
    {"orientation", StreamKind::kOrientation, true, true, "rad", "orientation :/body yaw"},
    {"velocity", StreamKind::kVelocity, true, false, "m/s", "velocity :/body x"},
    {"angular_velocity", StreamKind::kAngularVelocity, true, false, "rad/s",
     "angular_velocity :/body z"},
    {"joint", StreamKind::kJoint, false, false, "rad or m", "joint :/hip"},
    {"joint_velocity", StreamKind::kJointVelocity, false, false, "rad/s or m/s",
     "joint_velocity :/hip"},
    {"proximity", StreamKind::kProximity, false, false, "m", "proximity :/front"},
    {"force", StreamKind::kForce, true, false, "N", "force :/wrist z"},
    {"torque", StreamKind::kTorque, true, false, "N m", "torque :/wrist z"},
    {"distance", StreamKind::kDistance, false, false, "m", "distance :/clearance"},
    {"script", StreamKind::kScript, false, false, "", "script speed"},
};

struct ComponentInfo {
  const char* name;
  Component component;
};
constexpr ComponentInfo kXyz[] = {
    {"x", Component::kX}, {"y", Component::kY}, {"z", Component::kZ}, {"norm", Component::kNorm}};
constexpr ComponentInfo kAngles[] = {
    {"roll", Component::kRoll}, {"pitch", Component::kPitch}, {"yaw", Component::kYaw}};

std::vector<std::string> Words(std::string_view text) {
  std::vector<std::string> words;
  size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
    const size_t start = i;
    while (i < text.size() && text[i] != ' ' && text[i] != '\t') ++i;
    if (i > start) words.emplace_back(text.substr(start, i - start));
  }
  return words;
}

bool IsPath(const std::string& word) {
  return word[0] == '/' || word[0] == ':' || word.starts_with("./");
}

std::string Quoted(std::string_view text) {
  std::string q(1, '\'');
  q.append(text);
  q.push_back('\'');
  return q;
}

}  // namespace

void ParseStream(std::string_view text, std::vector<StreamSpec>* out) {
  const std::string what = "stream " + Quoted(text);
  // An explicit name: "height = position :/body z" (one word before '=').
  std::string name;
  std::string_view rest = text;
  if (const size_t eq = text.find('='); eq != std::string_view::npos) {
    const std::vector<std::string> before = Words(text.substr(0, eq));
    rest = text.substr(eq + 1);
    if (before.size() != 1 || rest.find('=') != std::string_view::npos)
      throw Error(what +
                  ": a stream's name is one word before one '=' (\"hip_yaw = joint :/hip\")");
    name = before[0];
  }
  if (name.find_first_of(",\"") != std::string::npos)
    throw Error(what + ": a stream's name may not hold ',' or '\"'");
  std::vector<std::string> words = Words(rest);
  if (words.empty())
    throw Error(what + ": expected '[NAME =] KIND [PATH] [COMPONENT]', such as " +
                Quoted(kKinds[0].example) + " or 'speed = script'");
  const KindInfo* kind = nullptr;
  for (const KindInfo& k : kKinds)
    if (words[0] == k.name) kind = &k;
  if (kind == nullptr) {
    std::vector<std::string> names;
    for (const KindInfo& k : kKinds) names.emplace_back(k.name);
    std::string hint = Suggest(words[0], names);
    if (hint.find("did you mean") != std::string::npos) {
      hint += " (kinds: ";
      for (size_t i = 0; i < names.size(); ++i) hint += (i ? ", " : "") + names[i];
      hint += ")";
    }
    throw Error(what + ": unknown stream kind " + Quoted(words[0]) + hint);
  }
  const std::string usage = " (for example " + Quoted(kind->example) + ")";

  // A script's stream: its name, once.
  if (kind->kind == StreamKind::kScript) {
    if (words.size() > 2 || (words.size() == 2 && !name.empty()))
      throw Error(what + ": a script stream takes its name once: 'script speed' or " +
                  "'speed = script'");
    if (words.size() == 2) name = words[1];
    if (name.empty()) throw Error(what + ": a script stream needs a name" + usage);
    out->push_back({name, StreamKind::kScript, Component::kNone, "", ""});
    return;
  }

  // An object's: its path, then a component.
  if (words.size() < 2 || !IsPath(words[1]))
    throw Error(what + ": " + Quoted(kind->name) +
                " needs an object path starting with '/', './' or ':'" + usage);
  const std::string& path = words[1];
  if (words.size() > 3)
    throw Error(what + ": too many words after the path " + Quoted(path) + usage);
  const std::string default_name = std::string(kind->name) + " " + path;
  if (!kind->vector) {
    if (words.size() == 3)
      throw Error(what + ": " + Quoted(kind->name) + " is one number and takes no component " +
                  Quoted(words[2]) + usage);
    out->push_back(
        {name.empty() ? default_name : name, kind->kind, Component::kNone, path, kind->unit});
    return;
  }
  const std::span<const ComponentInfo> components =
      kind->angles ? std::span<const ComponentInfo>(kAngles) : std::span<const ComponentInfo>(kXyz);
  if (words.size() == 3) {
    for (const ComponentInfo& c : components)
      if (words[2] == c.name) {
        out->push_back({name.empty() ? default_name + " " + c.name : name, kind->kind, c.component,
                        path, kind->unit});
        return;
      }
    std::string list;
    for (const ComponentInfo& c : components)
      list += (list.empty() ? "" : ", ") + std::string(c.name);
    throw Error(what + ": " + Quoted(kind->name) + " has no component " + Quoted(words[2]) +
                " (components: " + list + "; none: all three)");
  }
  // No component: x, y, z (or roll, pitch, yaw), three streams.
  for (size_t i = 0; i < 3; ++i)
    out->push_back(
        {name.empty() ? default_name + " " + components[i].name : name + "." + components[i].name,
         kind->kind, components[i].component, path, kind->unit});
}

}  // namespace swarmsim::graphs
