// Scene: object paths ("/robot/body", "./prox[3]", ":/wheel"): PathOf,
// FindObject and the message for a path that finds nothing. The rest of
// Scene is in scene.cc (objects, tree, poses, rows) and scene_copy.cc.
#include <array>
#include <charconv>
#include <string>
#include <string_view>
#include <vector>

#include "framework/error.h"
#include "framework/scene.h"
#include "framework/suggest.h"

namespace swarmsim {

// --- Paths --------------------------------------------------------------------------------

std::string Scene::PathOf(ObjectId id) const {
  std::vector<uint32_t> chain;
  for (int32_t s = static_cast<int32_t>(SlotOf(id)); s >= 0; s = parent_[s])
    chain.push_back(static_cast<uint32_t>(s));
  std::string path;
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) path += "/" + name_at(*it);
  return path;
}

namespace {

struct PathElement {
  std::string_view name;
  int index = -1;   // -1: the first match
  uint32_t id = 0;  // FindObject: the name's id in the scene's names
};

// Parses "a/b[2]/c" into `out` (cleared first); throws on a malformed index.
void SplitPath(std::string_view path, std::string_view full, std::vector<PathElement>* elements) {
  std::vector<PathElement>& out = *elements;
  out.clear();
  while (!path.empty()) {
    const size_t slash = path.find('/');
    std::string_view part = path.substr(0, slash);
    path = slash == std::string_view::npos ? std::string_view{} : path.substr(slash + 1);
    if (part.empty()) continue;
    PathElement e{part, -1, 0};
    if (part.back() == ']') {
      const size_t open = part.rfind('[');
      if (open == std::string_view::npos)
        throw Error("malformed object path '" + std::string(full) + "': missing '['");
      std::string_view digits = part.substr(open + 1, part.size() - open - 2);
      int value = 0;
      auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
      if (ec != std::errc() || ptr != digits.data() + digits.size() || value < 0)
        throw Error("malformed object path '" + std::string(full) + "': index '" +
                    std::string(digits) + "' is not a non-negative integer");
      e.name = part.substr(0, open);
      e.index = value;
    }
    out.push_back(e);
  }
}

// names.Find(name), remembering this thread's last few answers: a swarm's
// scripts and controllers look up the same few names ("prox", "leftMotor")
// once per robot at start, and in a pool holding a million robots' own
// names each lookup is a cache miss in its table. A remembered id is used
// only while the pool still holds it under that name (pools of other
// scenes, renames, removals).
uint32_t FindNameRemembered(const NamePool& names, std::string_view name) {
  struct Remembered {
    std::string name;
    uint32_t id = NamePool::kNone;
  };
  thread_local std::array<Remembered, 8> remembered;
  thread_local size_t next = 0;
  for (const Remembered& r : remembered)
    if (r.id != NamePool::kNone && r.name == name && names.Holds(r.id, name)) return r.id;
  const uint32_t id = names.Find(name);
  if (id != NamePool::kNone) {
    remembered[next].name.assign(name);
    remembered[next].id = id;
    next = (next + 1) % remembered.size();
  }
  return id;
}

// Where a path lookup's walk for one element stopped: the `index`th object
// named `name` below `root` (hierarchy order) is `match`, in the scene
// numbered `serial` at that structure version and rename count.
struct LookupCursor {
  uint64_t serial = 0, structure = 0, renames = 0;
  int32_t root = -1;
  uint32_t name = NamePool::kNone;
  int index = -1;
  int32_t match = -1;

  // May a walk for `next` (match unset) start after this one's match?
  bool Resumes(const LookupCursor& next) const {
    return match >= 0 && serial == next.serial && structure == next.structure &&
           renames == next.renames && root == next.root && name == next.name && index < next.index;
  }
};

}  // namespace

ObjectId Scene::FindObject(std::string_view path, ObjectId from) const {
  const std::string_view full = path;
  int32_t scope = -1;  // the subtree root whose descendants are searched
  bool search_descendants = true;
  if (path.starts_with("./") || path == ".") {
    if (!IsValid(from)) return {};
    scope = static_cast<int32_t>(from.index());
    path.remove_prefix(path.size() >= 2 ? 2 : 1);
  } else if (path.starts_with(":/") || path == ":") {
    if (!IsValid(from)) return {};
    int32_t root = static_cast<int32_t>(from.index());
    for (int32_t a = root; a >= 0; a = parent_[a])
      if (model_root_[a]) {
        root = a;
        break;
      }
    scope = root;
    path.remove_prefix(path.size() >= 2 ? 2 : 1);
  } else if (path.starts_with("/")) {
    path.remove_prefix(1);
    search_descendants = false;  // first element is a root object
  } else {
    throw Error("malformed object path '" + std::string(full) +
                "': start with '/' (absolute), './' (below this object) or ':/' (in this model)");
  }
  // The elements in a buffer of this thread's (robots' scripts and
  // controllers look up their objects by path at start, on every thread),
  // each name as its id: no object has a name the pool lacks, and the walk
  // compares ids, not strings.
  thread_local std::vector<PathElement> elements;
  SplitPath(path, full, &elements);
  if (elements.empty()) return scope < 0 ? ObjectId{} : IdAt(static_cast<uint32_t>(scope));
  for (PathElement& e : elements) {
    e.id = FindNameRemembered(names_, e.name);
    if (e.id == NamePool::kNone) return {};
  }

  // First element: roots (absolute) or any descendant of the scope; each
  // following one: descendants of the current match; hierarchy order (a
  // pre-order walk, children in insertion order, as CollectSubtree lists
  // them), without collecting the subtree: a robot's script looks up each
  // of its sensors at start.
  const auto next_in_subtree = [&](int32_t s, int32_t root) -> int32_t {
    if (first_child_[s] >= 0) return first_child_[s];
    for (; s != root; s = parent_[s])
      if (next_sibling_[s] >= 0) return next_sibling_[s];
    return -1;
  };
  int32_t current = -1;
  for (size_t k = 0; k < elements.size(); ++k) {
    const PathElement& e = elements[k];
    const int want = e.index < 0 ? 0 : e.index;
    int seen = 0;
    int32_t match = -1;
    const auto matches = [&](uint32_t c) { return name_[c] == e.id && seen++ == want; };
    if (k == 0 && !search_descendants) {
      for (uint32_t s = 0; s < generation_.size() && match < 0; ++s)
        if (alive_[s] && parent_[s] < 0 && matches(s)) match = static_cast<int32_t>(s);
    } else {
      const int32_t root = k == 0 ? scope : current;
      int32_t c = next_in_subtree(root, root);
      // A robot looking up ./prox[0], ./prox[1], ... in turn: resume after
      // this thread's last match of the name under the same object, if the
      // scene is the same, unchanged since, and that match came earlier.
      thread_local LookupCursor cursor;
      const LookupCursor here{serial_, structure_version_, renames_, root, e.id, want, -1};
      if (cursor.Resumes(here)) {
        seen = cursor.index + 1;
        c = next_in_subtree(cursor.match, root);
      }
      for (; c >= 0; c = next_in_subtree(c, root))
        if (matches(static_cast<uint32_t>(c))) {
          match = c;
          break;
        }
      if (match >= 0) {
        cursor = here;
        cursor.match = match;
      }
    }
    if (match < 0) return {};
    current = match;
  }
  return IdAt(static_cast<uint32_t>(current));
}

std::string Scene::ExplainMissingPath(std::string_view path, ObjectId from) const {
  // The same walk as FindObject, stopping at the element that matches nothing.
  const std::string_view full = path;
  std::vector<uint32_t> candidates;
  if (path.starts_with("./") || path.starts_with(":/")) {
    if (!IsValid(from)) return "";
    int32_t root = static_cast<int32_t>(from.index());
    if (path[0] == ':')
      for (int32_t a = root; a >= 0; a = parent_[a])
        if (model_root_[a]) {
          root = a;
          break;
        }
    CollectSubtree(static_cast<uint32_t>(root), &candidates);
    candidates.erase(candidates.begin());
  } else if (path.starts_with("/")) {
    for (uint32_t s = 0; s < generation_.size(); ++s)
      if (alive_[s] && parent_[s] < 0) candidates.push_back(s);
  } else {
    return "";
  }
  std::vector<PathElement> elements;
  SplitPath(path.substr(path[0] == '/' ? 1 : 2), full, &elements);
  for (const PathElement& e : elements) {
    int seen = 0;
    int32_t current = -1;
    for (uint32_t c : candidates) {
      if (name_at(c) != e.name) continue;
      if (seen++ == std::max(e.index, 0)) {
        current = static_cast<int32_t>(c);
        break;
      }
    }
    if (current >= 0) {
      candidates.clear();
      CollectSubtree(static_cast<uint32_t>(current), &candidates);
      candidates.erase(candidates.begin());
      continue;
    }
    // Too few objects of that name: say how many there are.
    const std::string name(e.name);
    if (seen > 0)
      return "; there " +
             std::string(seen == 1 ? "is 1 object" : "are " + std::to_string(seen) + " objects") +
             " named '" + name + "' there: " + name + "[0]" +
             (seen == 1 ? "" : ".." + name + "[" + std::to_string(seen - 1) + "]");
    // A misspelt name: the path with the nearest name of the objects it could reach.
    std::vector<std::string> names;
    for (uint32_t c : candidates) names.push_back(name_at(c));
    std::sort(names.begin(), names.end());
    names.erase(std::unique(names.begin(), names.end()), names.end());
    if (const std::string* nearest = NearestName(e.name, names)) {
      // Suggested only if the path with it names an object ('/bot#9/eye'
      // is not mended by '/bot#0/eye' when bot#0 has no eye either).
      const size_t at = static_cast<size_t>(e.name.data() - full.data());
      const std::string mended =
          std::string(full.substr(0, at)) + *nearest + std::string(full.substr(at + e.name.size()));
      if (!FindObject(mended, from).IsNull()) return "; did you mean '" + mended + "'?";
    }
    if (names.empty()) return "; there is no object there";
    constexpr size_t kListed = 20;
    std::string list;
    for (size_t i = 0; i < names.size() && i < kListed; ++i) list += (i ? ", " : "") + names[i];
    if (names.size() > kListed) list += ", ... (" + std::to_string(names.size()) + " names)";
    return "; the names there: " + list;
  }
  return "";
}

}  // namespace swarmsim
