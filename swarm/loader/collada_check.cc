// The check of a COLLADA file before assimp reads it (mesh_check.h).
#include <tinyxml2.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "framework/error.h"
#include "swarm/loader/check_text.h"
#include "swarm/loader/mesh.h"
#include "swarm/loader/mesh_check.h"

namespace swarmsim::loader {

namespace {

using tinyxml2::XMLElement;
using tinyxml2::XMLNode;

}  // namespace

// --- COLLADA --------------------------------------------------------------------------

namespace {

enum class Primitive {
  kLines,
  kLineStrips,
  kPolygons,
  kPolylist,
  kTriangles,
  kTriFans,
  kTriStrips
};

bool PrimitiveOf(std::string_view element, Primitive* kind) {
  static const std::pair<std::string_view, Primitive> kinds[] = {
      {"lines", Primitive::kLines},         {"linestrips", Primitive::kLineStrips},
      {"polygons", Primitive::kPolygons},   {"polylist", Primitive::kPolylist},
      {"triangles", Primitive::kTriangles}, {"trifans", Primitive::kTriFans},
      {"tristrips", Primitive::kTriStrips}};
  for (const auto& [text, value] : kinds)
    if (element == text) return *kind = value, true;
  return false;
}

// Every element below `root` in document order (pre-order), as assimp's
// XmlNodeIterator visits them; tinyxml2 bounds the depth.
void Descendants(const XMLElement* root, std::vector<const XMLElement*>* out) {
  out->clear();
  std::vector<const XMLElement*> stack;
  for (const XMLElement* c = root->LastChildElement(); c; c = c->PreviousSiblingElement())
    stack.push_back(c);
  while (!stack.empty()) {
    const XMLElement* e = stack.back();
    stack.pop_back();
    out->push_back(e);
    for (const XMLElement* c = e->LastChildElement(); c; c = c->PreviousSiblingElement())
      stack.push_back(c);
  }
}

// An element's text (after Sanitize: one text node, wherever it stands
// among the children, as assimp's XML reader finds it).
std::string_view TextOf(const XMLElement* e) {
  for (const XMLNode* c = e->FirstChild(); c; c = c->NextSibling())
    if (const tinyxml2::XMLText* text = c->ToText()) return text->Value();
  return {};
}

// "#id" -> "id"; "" for anything else.
std::string_view Fragment(const char* url) {
  if (url == nullptr || url[0] != '#') return {};
  return std::string_view(url + 1);
}

class ColladaCheck {
 public:
  ColladaCheck(const std::string& bytes, const std::string& name) : bytes_(bytes), name_(name) {}
  std::string Run();

 private:
  struct Array {
    const XMLElement* e = nullptr;
    uint64_t values = 0;  // numbers assimp reads (0 for a Name_array or IDREF_array)
  };
  struct Accessor {
    const XMLElement* e = nullptr;
    uint64_t count = 0;
    int size = 0;  // assimp's mSize: typed params, a float4x4 as 16
  };
  struct NodeTotals {
    double nodes = 0, triangles = 0;
    int depth = 0;
  };

  [[noreturn]] void Fail(const XMLElement* e, const std::string& message) const {
    loader::Fail(name_, e ? e->GetLineNum() : 0, message);
  }
  // The text of a list of numbers (<p>, <vcount>, <float_array>). assimp
  // separates numbers by space, tab, CR, LF and form feed only: at any other
  // character its integer reader neither advances nor fails, and the <p>
  // loop appends zeros until memory runs out (1.6 GB for three vertical
  // tabs), so a vertical tab is refused here.
  std::string_view NumbersOf(const XMLElement* e) const {
    const std::string_view text = TextOf(e);
    if (const size_t at = text.find('\v'); at != std::string_view::npos)
      Fail(e, "<" + std::string(e->Name()) +
                  "> separates its numbers with a vertical tab (0x0B); use spaces");
    return text;
  }
  uint64_t CountAttribute(const XMLElement* e, const char* key, uint64_t fallback,
                          uint64_t max = 4294967295u) const;
  void Sanitize();
  void CheckArrays(const XMLElement* geometries);
  void CheckSources(const XMLElement* geometries);
  void CheckAccessor(const XMLElement* source, const XMLElement* accessor);
  double CheckMesh(const XMLElement* mesh);
  double CheckPrimitive(const XMLElement* element, Primitive kind,
                        const std::map<std::string_view, uint64_t>& vertex_limit);
  const Accessor* AccessorOf(const XMLElement* input) const;
  void CheckReference(const XMLElement* input, bool per_vertex,
                      const std::map<std::string_view, uint64_t>& vertex_limit) const;
  NodeTotals Visit(const XMLElement* node, int depth);

  const std::string& bytes_;
  const std::string& name_;
  tinyxml2::XMLDocument doc_{true, tinyxml2::PRESERVE_WHITESPACE};
  std::unordered_map<std::string_view, Array> arrays_;               // by id
  std::unordered_map<std::string_view, const XMLElement*> sources_;  // by id
  std::unordered_map<std::string_view, Accessor> accessors_;         // by the <source>'s id
  std::unordered_map<std::string_view, double> geometry_triangles_;
  std::unordered_multimap<std::string_view, const XMLElement*> nodes_;  // by id and by name
  std::unordered_map<const XMLElement*, NodeTotals> visited_;
  std::unordered_map<const XMLElement*, bool> visiting_;
  double triangles_ = 0, corners_ = 0;
};

uint64_t ColladaCheck::CountAttribute(const XMLElement* e, const char* key, uint64_t fallback,
                                      uint64_t max) const {
  const char* text = e->Attribute(key);
  if (text == nullptr) return fallback;
  uint64_t value = 0;
  if (!ParseUnsigned(text, max, &value))
    Fail(e, "<" + std::string(e->Name()) + " " + key + "=\"" + Shown(text) +
                "\"> must be a non-negative integer of at most " +
                Count(static_cast<int64_t>(max)));
  return value;
}

// Keeps what the loader uses (geometry, nodes, materials and their effects
// and images, the unit), drops comments, and joins each element's text
// into one node (assimp reads an element's first text node only).
void ColladaCheck::Sanitize() {
  XMLElement* root = doc_.RootElement();
  static const std::string_view kKept[] = {
      "asset",           "library_geometries", "library_visual_scenes", "library_nodes",
      "library_effects", "library_materials",  "library_images",        "scene"};
  // The geometry each controller shows: its skin's or morph's source,
  // through other controllers.
  std::unordered_map<std::string, std::string> controller_source;
  for (const XMLElement* library = root->FirstChildElement("library_controllers"); library;
       library = library->NextSiblingElement("library_controllers"))
    for (const XMLElement* c = library->FirstChildElement("controller"); c;
         c = c->NextSiblingElement("controller")) {
      const XMLElement* skin = c->FirstChildElement("skin");
      if (!skin) skin = c->FirstChildElement("morph");
      if (c->Attribute("id") && skin)
        controller_source[c->Attribute("id")] = std::string(Fragment(skin->Attribute("source")));
    }
  // Outside the root: the declaration only (no DOCTYPE, no comments).
  std::vector<XMLNode*> drop;
  for (XMLNode* c = doc_.FirstChild(); c; c = c->NextSibling())
    if (c != root && !c->ToDeclaration()) drop.push_back(c);
  std::vector<XMLElement*> stack{root};
  while (!stack.empty()) {
    XMLElement* e = stack.back();
    stack.pop_back();
    // An instance of a skin or morph: an instance of its geometry.
    if (std::string_view(e->Name()) == "instance_controller") {
      std::string id(Fragment(e->Attribute("url")));
      for (int hops = 0; hops < 8 && controller_source.contains(id); ++hops)
        id = controller_source[id];
      if (id.empty() || controller_source.contains(id)) {
        drop.push_back(e);
        continue;
      }
      e->SetName("instance_geometry");
      e->SetAttribute("url", ("#" + id).c_str());
    }
    // Text split by comments or CDATA sections, as one node.
    std::string text;
    tinyxml2::XMLText* first_text = nullptr;
    for (XMLNode* c = e->FirstChild(); c; c = c->NextSibling()) {
      if (c->ToComment() || c->ToUnknown() || c->ToDeclaration()) {
        drop.push_back(c);
      } else if (tinyxml2::XMLText* t = c->ToText()) {
        text += t->Value();
        if (first_text) {
          drop.push_back(c);
        } else {
          first_text = t;
        }
      } else if (XMLElement* child = c->ToElement()) {
        const bool kept = e != root || std::find(std::begin(kKept), std::end(kKept),
                                                 child->Name()) != std::end(kKept);
        if (kept) {
          stack.push_back(child);
        } else {
          drop.push_back(child);
        }
      }
    }
    if (first_text && text.size() != std::strlen(first_text->Value()))
      first_text->SetValue(text.c_str());
  }
  // (Nothing dropped lies inside something else dropped: a dropped
  // element's children are never visited.)
  for (XMLNode* n : drop) (n->Parent() ? n->Parent() : &doc_)->DeleteChild(n);
}

// The data arrays below <library_geometries>: counts within their values,
// numbers finite; ids unique (assimp keeps the last of a repeated id).
void ColladaCheck::CheckArrays(const XMLElement* geometries) {
  std::vector<const XMLElement*> all;
  Descendants(geometries, &all);
  for (const XMLElement* e : all) {
    const std::string_view kind = e->Name();
    const bool numbers = kind == "float_array";
    if (!numbers && kind != "Name_array" && kind != "IDREF_array") continue;
    const char* id = e->Attribute("id");
    const uint64_t count = CountAttribute(e, "count", 0);
    uint64_t seen = 0;
    ForEachToken(NumbersOf(e), [&](std::string_view t) {
      if (seen >= count) return false;
      double v;
      if (numbers && !ParseFinite(t, &v))
        Fail(e, "<float_array" + std::string(id ? " id='" + std::string(id) + "'" : "") +
                    "> value " + Quoted(t) + " is not a finite number");
      ++seen;
      return true;
    });
    if (seen < count)
      Fail(e, "<" + std::string(kind) + " count=\"" + std::to_string(count) + "\"> holds only " +
                  Count(static_cast<int64_t>(seen)) + " values");
    if (id == nullptr) continue;
    if (const auto it = arrays_.find(id); it != arrays_.end())
      Fail(e, "array id '" + std::string(id) + "' is used twice (first at line " +
                  std::to_string(it->second.e->GetLineNum()) + ")");
    arrays_[id] = {e, numbers ? count : 0};
  }
}

// Each <source>'s accessor (assimp's: the <accessor> of any
// <technique_common> below it, the last one winning); source ids unique.
void ColladaCheck::CheckSources(const XMLElement* geometries) {
  std::vector<const XMLElement*> all, below;
  Descendants(geometries, &all);
  for (const XMLElement* e : all) {
    if (std::string_view(e->Name()) != "source") continue;
    if (const char* id = e->Attribute("id")) {
      if (const auto it = sources_.find(id); it != sources_.end())
        Fail(e, "source id '" + std::string(id) + "' is used twice (first at line " +
                    std::to_string(it->second->GetLineNum()) + ")");
      sources_[id] = e;
    }
    Descendants(e, &below);
    for (const XMLElement* t : below)
      if (std::string_view(t->Name()) == "technique_common")
        if (const XMLElement* accessor = t->FirstChildElement("accessor"))
          CheckAccessor(e, accessor);
  }
}

// An accessor reads values offset + i * stride + (its params' places) of
// its array, for i below count: all within the array.
void ColladaCheck::CheckAccessor(const XMLElement* source, const XMLElement* accessor) {
  const uint64_t count = CountAttribute(accessor, "count", 0, 2147483647);
  const uint64_t offset = CountAttribute(accessor, "offset", 0);
  const uint64_t stride = CountAttribute(accessor, "stride", 1);
  // Params: their places (X, Y, Z, ... take the place of their order) and assimp's size.
  uint64_t last_place = 0;
  int params = 0, size = 0;
  std::vector<const XMLElement*> below;
  Descendants(accessor, &below);
  for (const XMLElement* p : below) {
    if (std::string_view(p->Name()) != "param") continue;
    static const std::string_view kPlaced[] = {"X", "Y", "Z", "R", "G", "B",
                                               "A", "S", "T", "P", "U", "V"};
    const char* param_name = p->Attribute("name");
    if (param_name && std::find(std::begin(kPlaced), std::end(kPlaced),
                                std::string_view(param_name)) != std::end(kPlaced))
      last_place = std::max<uint64_t>(last_place, static_cast<uint64_t>(params));
    if (const char* type = p->Attribute("type"))
      size += std::string_view(type) == "float4x4" ? 16 : 1;
    ++params;
    size = std::min(size, 1 << 20);
  }
  const char* id = source->Attribute("id");
  const std::string_view array_id = Fragment(accessor->Attribute("source"));
  if (const auto it = arrays_.find(array_id); it != arrays_.end() && count > 0) {
    const uint64_t reach = offset + (count - 1) * stride + last_place + 1;
    if (reach > it->second.values)
      Fail(accessor, "<accessor count=\"" + std::to_string(count) + "\" stride=\"" +
                         std::to_string(stride) + "\" offset=\"" + std::to_string(offset) +
                         "\"> reads " + Count(static_cast<int64_t>(reach)) + " numbers of array '" +
                         std::string(array_id) + "' (line " +
                         std::to_string(it->second.e->GetLineNum()) + "), which has " +
                         Count(static_cast<int64_t>(it->second.values)));
  }
  if (id != nullptr) accessors_[id] = {accessor, count, size};
}

const ColladaCheck::Accessor* ColladaCheck::AccessorOf(const XMLElement* input) const {
  const auto it = accessors_.find(Fragment(input->Attribute("source")));
  return it == accessors_.end() ? nullptr : &it->second;
}

// An <input> of a <vertices> (`per_vertex`) or of a primitive element names
// what assimp resolves, or assimp's own error would name no line ("Unable
// to resolve library reference", "Unsupported vertex referencing scheme"):
// a primitive's VERTEX input the mesh's <vertices>; any other input of a
// semantic assimp reads a <source> with an accessor, whose array exists.
void ColladaCheck::CheckReference(const XMLElement* input, bool per_vertex,
                                  const std::map<std::string_view, uint64_t>& vertex_limit) const {
  static const std::string_view kRead[] = {"POSITION", "NORMAL",     "TEXCOORD", "COLOR",
                                           "TANGENT",  "TEXTANGENT", "BINORMAL", "TEXBINORMAL"};
  const char* semantic_text = input->Attribute("semantic");
  const std::string_view semantic = semantic_text ? semantic_text : "";
  const char* source_text = input->Attribute("source");
  const std::string what = "<input semantic=\"" + Shown(semantic) + "\" source=\"" +
                           Shown(source_text ? source_text : "") + "\">";
  const std::string_view id = Fragment(source_text);
  if (semantic == "VERTEX" && !per_vertex) {
    if (vertex_limit.contains(id)) return;
    std::string ids;
    for (const auto& [vertices_id, limit] : vertex_limit)
      ids += (ids.empty() ? "'" : ", '") + std::string(vertices_id) + "'";
    Fail(input, what + " must name its <mesh>'s <vertices> (" +
                    (ids.empty() ? std::string("the mesh has none") : "id " + ids) + ")");
  }
  if (std::find(std::begin(kRead), std::end(kRead), semantic) == std::end(kRead)) return;
  const auto source = sources_.find(id);
  if (source == sources_.end())
    Fail(input, what + ": the file's geometries have no <source> with id " + Quoted(id));
  const auto accessor = accessors_.find(id);
  if (accessor == accessors_.end())
    Fail(input, what + ": <source> " + Quoted(id) + " (line " +
                    std::to_string(source->second->GetLineNum()) +
                    ") has no <technique_common><accessor>");
  const std::string_view array_id = Fragment(accessor->second.e->Attribute("source"));
  if (!arrays_.contains(array_id))
    Fail(accessor->second.e,
         "<accessor source=\"" +
             Shown(accessor->second.e->Attribute("source") ? accessor->second.e->Attribute("source")
                                                           : "") +
             "\">: the file's geometries have no array with id " + Quoted(array_id));
}

// A <mesh>'s primitive elements; returns its triangles.
double ColladaCheck::CheckMesh(const XMLElement* mesh) {
  std::vector<const XMLElement*> below;
  Descendants(mesh, &below);
  // A VERTEX input's indices are below the count of every input of the
  // <vertices> it names (assimp looks each up with the same index).
  std::map<std::string_view, uint64_t> vertex_limit;  // by <vertices> id
  for (const XMLElement* e : below) {
    if (std::string_view(e->Name()) != "vertices") continue;
    uint64_t limit = UINT64_MAX;
    for (const XMLElement* input = e->FirstChildElement("input"); input;
         input = input->NextSiblingElement("input")) {
      CheckReference(input, /*per_vertex=*/true, vertex_limit);
      if (const Accessor* a = AccessorOf(input)) {
        limit = std::min(limit, a->count);
        if (input->Attribute("semantic", "COLOR") && a->size > 4)
          Fail(input, "<input semantic=\"COLOR\"> names an accessor of " + std::to_string(a->size) +
                          " components (at most 4)");
      }
    }
    vertex_limit[e->Attribute("id") ? e->Attribute("id") : ""] = limit;
  }
  double triangles = 0;
  for (const XMLElement* e : below) {
    Primitive kind;
    if (PrimitiveOf(e->Name(), &kind)) triangles += CheckPrimitive(e, kind, vertex_limit);
  }
  return triangles;
}

// One primitive element (<triangles>, <polylist>, ...), as assimp reads it:
// its inputs, <vcount> and <p> in document order, <p> read only when the
// element's count is positive. Returns its triangles.
double ColladaCheck::CheckPrimitive(const XMLElement* element, Primitive kind,
                                    const std::map<std::string_view, uint64_t>& vertex_limit) {
  const std::string what = "<" + std::string(element->Name()) + ">";
  const uint64_t count = CountAttribute(element, "count", 0);
  struct Input {
    uint64_t offset;
    uint64_t limit;  // indices below this
    std::string semantic, source;
    const XMLElement* e;
  };
  std::vector<Input> inputs;
  std::vector<uint64_t> vcount;
  bool vcount_seen = false;
  int p_count = 0;
  double triangles = 0;
  std::vector<const XMLElement*> below;
  Descendants(element, &below);
  for (const XMLElement* e : below) {
    const std::string_view kind_name = e->Name();
    if (kind_name == "input") {
      Input in;
      in.e = e;
      in.offset = CountAttribute(e, "offset", 0, 63);
      in.semantic = e->Attribute("semantic") ? e->Attribute("semantic") : "";
      in.source = std::string(Fragment(e->Attribute("source")));
      in.limit = UINT64_MAX;
      if (in.semantic == "VERTEX") {
        if (const auto it = vertex_limit.find(in.source); it != vertex_limit.end())
          in.limit = it->second;
      } else if (const Accessor* a = AccessorOf(e)) {
        in.limit = a->count;
        if (in.semantic == "COLOR" && a->size > 4)
          Fail(e, "<input semantic=\"COLOR\"> names an accessor of " + std::to_string(a->size) +
                      " components (at most 4)");
      }
      inputs.push_back(in);
    } else if (kind_name == "vcount" && count > 0) {
      if (vcount_seen) Fail(e, what + " has a second <vcount>");
      vcount_seen = true;
      ForEachToken(NumbersOf(e), [&](std::string_view t) {
        if (vcount.size() >= count) return false;
        uint64_t v = 0;
        if (!ParseUnsigned(t, 1u << 30, &v) || v == 0)
          Fail(e, "<vcount> value " + Quoted(t) + " is not a positive integer");
        if (v > static_cast<uint64_t>(kMaxFaceCorners))
          Fail(e, "<vcount>: a face of " + Count(static_cast<int64_t>(v)) + " corners; at most " +
                      Count(kMaxFaceCorners) + " (split a larger polygon into smaller faces)");
        vcount.push_back(v);
        return true;
      });
      if (vcount.size() < count)
        Fail(e, "<vcount> holds " + Count(static_cast<int64_t>(vcount.size())) +
                    " values for the " + Count(static_cast<int64_t>(count)) + " polygons of " +
                    what + " (line " + std::to_string(element->GetLineNum()) + ")");
    } else if (kind_name == "p") {
      ++p_count;
      if (count == 0) continue;  // assimp reads no index then
      uint64_t offsets = 1;
      bool has_vertex = false;
      for (const Input& in : inputs) {
        offsets = std::max(offsets, in.offset + 1);
        has_vertex = has_vertex || in.semantic == "VERTEX";
      }
      if (!has_vertex)
        Fail(e, what + " (line " + std::to_string(element->GetLineNum()) +
                    ") has no <input semantic=\"VERTEX\"> before its <p>");
      // The smallest limit of the inputs at each offset.
      std::vector<uint64_t> limit(offsets, UINT64_MAX);
      std::vector<const Input*> limiting(offsets, nullptr);
      for (const Input& in : inputs)
        if (in.limit < limit[in.offset]) limit[in.offset] = in.limit, limiting[in.offset] = &in;
      uint64_t tokens = 0;
      ForEachToken(NumbersOf(e), [&](std::string_view t) {
        uint64_t index = 0;
        if (!ParseUnsigned(t, 2147483647, &index))
          Fail(e, "<p> index " + Quoted(t) + " is not a non-negative integer");
        const uint64_t offset = tokens % offsets;
        if (index >= limit[offset])
          Fail(e, "<p> index " + std::to_string(index) + " (input " + limiting[offset]->semantic +
                      ") is beyond the " + Count(static_cast<int64_t>(limit[offset])) +
                      " entries of '" + limiting[offset]->source + "'");
        ++tokens;
        if (tokens > 3 * static_cast<uint64_t>(kMaxMeshTriangles) * offsets)
          Fail(e, "<p> has more than " + Count(3 * kMaxMeshTriangles) +
                      " corners, the limit for a mesh file");
        return true;
      });
      const uint64_t points = tokens / offsets;
      corners_ += static_cast<double>(points);
      const auto needs = [&](uint64_t n, const std::string& why) {
        if (tokens != n * offsets)
          Fail(e, "<p> holds " + Count(static_cast<int64_t>(tokens)) + " indices, but " + why +
                      " with " + std::to_string(offsets) + " index" + (offsets == 1 ? "" : "es") +
                      " per corner need " + Count(static_cast<int64_t>(n * offsets)));
      };
      switch (kind) {
        case Primitive::kTriangles:
          needs(3 * count, what + " count=\"" + std::to_string(count) + "\" (line " +
                               std::to_string(element->GetLineNum()) + ")");
          triangles += static_cast<double>(count);
          break;
        case Primitive::kPolylist: {
          if (!vcount_seen)
            Fail(e, what + " (line " + std::to_string(element->GetLineNum()) +
                        ") needs its <vcount> before its <p>");
          uint64_t sum = 0;
          for (uint64_t v : vcount) {
            sum += v;
            triangles += v >= 3 ? static_cast<double>(v - 2) : 0;
          }
          needs(sum, "the " + Count(static_cast<int64_t>(count)) + " polygons of its <vcount>");
          break;
        }
        case Primitive::kLines: break;
        case Primitive::kLineStrips:
        case Primitive::kPolygons:
        case Primitive::kTriFans:
        case Primitive::kTriStrips: {
          const uint64_t least = kind == Primitive::kLineStrips ? 2 : 3;
          if (tokens % offsets != 0 || points < least)
            Fail(e, "<p> of " + what + " holds " + Count(static_cast<int64_t>(tokens)) +
                        " indices: " + std::to_string(offsets) + " per corner, at least " +
                        std::to_string(least) + " corners");
          if (kind == Primitive::kPolygons && points > static_cast<uint64_t>(kMaxFaceCorners))
            Fail(e, "<p> of <polygons>: a face of " + Count(static_cast<int64_t>(points)) +
                        " corners; at most " + Count(kMaxFaceCorners) +
                        " (split a larger polygon into smaller faces)");
          if (kind != Primitive::kLineStrips) triangles += static_cast<double>(points - 2);
          break;
        }
      }
      // What the inputs name resolves (assimp resolves them as it reads the <p>).
      for (const Input& in : inputs) CheckReference(in.e, /*per_vertex=*/false, vertex_limit);
    }
  }
  // assimp asserts that the <p> elements made `count` primitives.
  const bool one_p = kind == Primitive::kTriangles || kind == Primitive::kPolylist;
  if (one_p && count > 0 && p_count != 1)
    Fail(element, what + " count=\"" + std::to_string(count) + "\" needs exactly one <p>, not " +
                      std::to_string(p_count) + " (one <" +
                      (kind == Primitive::kTriangles ? "triangles" : "polylist") +
                      "> element per <p>)");
  // A <polygons> <p> is one polygon (assimp asserts their number is the
  // count); strips and fans read nothing at count 0, and an empty strip
  // wraps their size around.
  if (kind == Primitive::kPolygons && static_cast<uint64_t>(p_count) != count)
    Fail(element, what + " count=\"" + std::to_string(count) + "\" has " + std::to_string(p_count) +
                      " <p> (one per polygon)");
  const bool strips = kind == Primitive::kTriFans || kind == Primitive::kTriStrips ||
                      kind == Primitive::kLineStrips;
  if (strips && count == 0 && p_count > 0)
    Fail(element,
         what + " count=\"0\" has " + std::to_string(p_count) + " <p> (one per strip or fan)");
  return triangles;
}

std::string TooDeep() {
  return "the node hierarchy is more than " + std::to_string(kMaxColladaNodeDepth) +
         " levels deep (nested nodes and <instance_node>s)";
}

// Nodes, nested and instanced (<instance_node> names a node by id or name):
// nodes made, triangles shown, depth; no node inside itself.
ColladaCheck::NodeTotals ColladaCheck::Visit(const XMLElement* node, int depth) {
  if (const auto it = visited_.find(node); it != visited_.end()) {
    if (depth + it->second.depth > kMaxColladaNodeDepth) Fail(node, TooDeep());
    return it->second;
  }
  if (depth > kMaxColladaNodeDepth) Fail(node, TooDeep());
  if (visiting_[node])
    Fail(node, "node '" + std::string(node->Attribute("id") ? node->Attribute("id") : "") +
                   "' contains itself (through <instance_node>)");
  visiting_[node] = true;
  NodeTotals totals{1, 0, 1};
  const auto add = [&](const NodeTotals& t) {
    totals.nodes += t.nodes;
    totals.triangles += t.triangles;
    totals.depth = std::max(totals.depth, t.depth + 1);
  };
  for (const XMLElement* c = node->FirstChildElement(); c; c = c->NextSiblingElement()) {
    const std::string_view kind = c->Name();
    if (kind == "node") {
      add(Visit(c, depth + 1));
    } else if (kind == "instance_node") {
      // The largest of the nodes the url may name (assimp takes one).
      NodeTotals most{0, 0, 0};
      const auto [begin, end] = nodes_.equal_range(Fragment(c->Attribute("url")));
      for (auto it = begin; it != end; ++it) {
        const NodeTotals t = Visit(it->second, depth + 1);
        most = {std::max(most.nodes, t.nodes), std::max(most.triangles, t.triangles),
                std::max(most.depth, t.depth)};
      }
      add(most);
    } else if (kind == "instance_geometry") {
      const auto it = geometry_triangles_.find(Fragment(c->Attribute("url")));
      if (it != geometry_triangles_.end()) totals.triangles += it->second;
    }
  }
  if (totals.nodes > static_cast<double>(kMaxColladaNodes))
    Fail(node, "the node hierarchy makes more than " + Count(kMaxColladaNodes) +
                   " nodes, each instance counted (the limit for a mesh file)");
  if (totals.triangles > static_cast<double>(kMaxMeshTriangles))
    Fail(node, "the nodes show more than " + Count(kMaxMeshTriangles) +
                   " triangles, each instance counted, the limit for a mesh file");
  if (depth + totals.depth > kMaxColladaNodeDepth) Fail(node, TooDeep());
  visiting_[node] = false;
  visited_[node] = totals;
  return totals;
}

std::string ColladaCheck::Run() {
  // Elements before parsing: tinyxml2 holds about 100 bytes per element.
  int64_t elements = 0;
  for (size_t i = bytes_.find('<'); i != std::string::npos; i = bytes_.find('<', i + 1))
    if (i + 1 < bytes_.size() &&
        (std::isalpha(static_cast<unsigned char>(bytes_[i + 1])) || bytes_[i + 1] == '_'))
      if (++elements > kMaxColladaElements)
        loader::Fail(name_, 0,
                     "has more than " + Count(kMaxColladaElements) +
                         " XML elements, the limit for a COLLADA file");
  CheckXmlHasNoDtd(bytes_, name_, "COLLADA");
  if (doc_.Parse(bytes_.data(), bytes_.size()) != tinyxml2::XML_SUCCESS) {
    int line = 0;
    if (const std::string nesting = loader::XmlNestingProblem(bytes_, &line); !nesting.empty())
      loader::Fail(name_, line, "malformed XML: " + nesting);
    loader::Fail(name_, doc_.ErrorLineNum(),
                 "malformed XML: " + loader::XmlParseErrorInWords(doc_.ErrorID(), doc_.ErrorStr()));
  }
  const XMLElement* root = doc_.RootElement();
  if (!root || std::string_view(root->Name()) != "COLLADA")
    Fail(root, "a COLLADA file's root element must be <COLLADA>, not <" +
                   std::string(root ? root->Name() : "") + ">");
  Sanitize();

  // Geometry: arrays, accessors, primitives.
  for (const XMLElement* library = root->FirstChildElement("library_geometries"); library;
       library = library->NextSiblingElement("library_geometries"))
    CheckArrays(library);
  for (const XMLElement* library = root->FirstChildElement("library_geometries"); library;
       library = library->NextSiblingElement("library_geometries"))
    CheckSources(library);
  for (const XMLElement* library = root->FirstChildElement("library_geometries"); library;
       library = library->NextSiblingElement("library_geometries"))
    for (const XMLElement* g = library->FirstChildElement("geometry"); g;
         g = g->NextSiblingElement("geometry")) {
      double triangles = 0;
      for (const XMLElement* m = g->FirstChildElement("mesh"); m; m = m->NextSiblingElement("mesh"))
        triangles += CheckMesh(m);
      triangles_ += triangles;
      if (const char* id = g->Attribute("id"); id && !geometry_triangles_.contains(id))
        geometry_triangles_[id] = triangles;
      if (triangles_ > static_cast<double>(kMaxMeshTriangles))
        CheckTriangleCount(name_, g->GetLineNum(), kMaxMeshTriangles + 1,
                           "the geometries up to here hold");
    }
  if (corners_ > 3.0 * static_cast<double>(kMaxMeshTriangles))
    loader::Fail(name_, 0,
                 "its primitives have more than " + Count(3 * kMaxMeshTriangles) +
                     " corners, the limit for a mesh file");

  // Nodes: every <node> and <visual_scene> (assimp keeps visual scenes
  // among its nodes), by id and by name, then each visited in file order.
  std::vector<const XMLElement*> nodes;
  for (const char* library_name : {"library_visual_scenes", "library_nodes"})
    for (const XMLElement* library = root->FirstChildElement(library_name); library;
         library = library->NextSiblingElement(library_name)) {
      std::vector<const XMLElement*> all;
      Descendants(library, &all);
      for (const XMLElement* e : all) {
        const std::string_view kind = e->Name();
        if (kind != "node" && kind != "visual_scene") continue;
        nodes.push_back(e);
        for (const char* key : {"id", "name"})
          if (const char* v = e->Attribute(key)) nodes_.emplace(v, e);
      }
    }
  for (const XMLElement* node : nodes) Visit(node, 0);
  // The scene: a visual scene the file has (assimp's error would name no line).
  if (const XMLElement* scene = root->FirstChildElement("scene"))
    if (const XMLElement* instance = scene->FirstChildElement("instance_visual_scene")) {
      const char* url = instance->Attribute("url");
      const auto [begin, end] = nodes_.equal_range(Fragment(url));
      if (std::none_of(begin, end, [](const auto& n) {
            return std::string_view(n.second->Name()) == "visual_scene";
          }))
        Fail(instance, "<instance_visual_scene url=\"" + Shown(url ? url : "") +
                           "\">: the file has no <visual_scene> with id " + Quoted(Fragment(url)));
    }
  // The unit: a positive number of metres (assimp reads "abc" as 0: every
  // vertex at the origin, "no triangles" without a line).
  if (const XMLElement* asset = root->FirstChildElement("asset"))
    if (const XMLElement* unit = asset->FirstChildElement("unit"))
      if (const char* meter = unit->Attribute("meter")) {
        std::string_view text = meter;
        while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front())))
          text.remove_prefix(1);
        while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())))
          text.remove_suffix(1);
        double value = 0;
        if (!ParseFinite(text, &value) || !(value > 0))
          Fail(unit,
               "<unit meter=\"" + Shown(meter) + "\"> must be a positive number (metres per unit)");
      }

  tinyxml2::XMLPrinter printer(nullptr, /*compact=*/true);
  doc_.Print(&printer);
  return std::string(printer.CStr(), static_cast<size_t>(std::max(printer.CStrSize() - 1, 0)));
}

}  // namespace

std::string CheckColladaBytes(const std::string& bytes, const std::string& name) {
  return ColladaCheck(bytes, name).Run();
}

}  // namespace swarmsim::loader
