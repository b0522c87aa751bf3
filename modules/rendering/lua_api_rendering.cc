// sim.* vision sensors, shape colours and lights (the Lua area of the
// vision_sensor and light types):
//   sim.getVisionSensorImg(h [, 1]) -> bytes (RGB, rows top to bottom: the
//     filter chain's image, or with 1 the camera's), {width, height}
//   sim.getVisionSensorDepth(h) -> {d, ...} (m along the view axis; far where
//     nothing), {width, height}
//   sim.getVisionSensorRes(h) -> {width, height}
//   sim.readVisionSensor(h) -> result, packet1 (CoppeliaSim's 15 values:
//     minima, maxima and means of intensity, red, green, blue and depth),
//     then a packet per filter element that gives values
//   sim.getVisionSensorBlobs(h) -> {{pixels, color, x, y, u, v, box, orientation}, ...}
//   sim.setShapeColor(h, {r, g, b}) (or CoppeliaSim's (h, nil, 0, {r, g, b})),
//   sim.getShapeColor(h) -> {r, g, b}
//   sim.setLightOn(h, on), sim.getLightOn(h), sim.setLightColor(h, {r, g, b})
// Images are those of the last sense phase the sensor rendered in (its
// `rate`); a robot's scripts may change only their own robot's shapes and
// lights (the renderer reads them in the next sense phase, after every
// script of the step has run).
#include <algorithm>
#include <cmath>
#include <string>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/rendering/objects.h"

namespace swarmsim::rendering {

namespace {

template <typename Row>
Row& RowOf(lua_State* L, int arg, const char* type_name, const char* what) {
  Scene& scene = *Context(L).scene;
  const ObjectId id = CheckObject(L, arg);
  const uint32_t slot = scene.SlotOf(id);
  ObjectType type;
  if (!scene.FindType(type_name, &type) || scene.type_at(slot) != type)
    throw Error("'" + scene.PathOf(id) + "' is a " + scene.type_name(scene.type_at(slot)) +
                ", not " + what);
  return static_cast<Rows<Row>*>(scene.rows(type))->rows[scene.row_at(slot)];
}

VisionSensorRow& SensorOf(lua_State* L) {
  return RowOf<VisionSensorRow>(L, 1, "vision_sensor", "a vision sensor");
}

// Only the script's own robot (or, for the main script, anything).
void CheckOwn(lua_State* L, ObjectId id, const char* what) {
  const LuaContext& c = Context(L);
  if (c.instance >= 0 && c.scene->instance_of(id) != c.instance)
    throw Error(std::string("a robot's script may change only its own robot's ") + what + " ('" +
                c.scene->PathOf(id) + "' belongs to another robot or to the scene)");
}

void PushResolution(lua_State* L, int width, int height) {
  lua_createtable(L, 2, 0);
  lua_pushinteger(L, width);
  lua_rawseti(L, -2, 1);
  lua_pushinteger(L, height);
  lua_rawseti(L, -2, 2);
}

void PushResolution(lua_State* L, const Lens& lens) { PushResolution(L, lens.width, lens.height); }

const Image& ImageOf(const VisionSensorRow& s) {
  if (s.rendered_step < 0) throw Error("the vision sensor has not rendered an image yet");
  return s.image;
}

// The filtered image when the sensor has a chain (CoppeliaSim's), else the
// camera's; sim.getVisionSensorImg(h, 1): always the camera's.
int GetVisionSensorImg(lua_State* L) {
  const VisionSensorRow& s = SensorOf(L);
  const bool raw = !lua_isnoneornil(L, 2) && ArgInteger(L, 2) == 1;
  const Image& camera = ImageOf(s);  // (throws before the first image)
  const Image& image = raw || s.filters.empty() ? camera : s.output.image;
  lua_pushlstring(L, reinterpret_cast<const char*>(image.rgb.data()), image.rgb.size());
  PushResolution(L, image.width, image.height);
  return 2;
}

int GetVisionSensorDepth(lua_State* L) {
  const VisionSensorRow& s = SensorOf(L);
  const Image& image = ImageOf(s);
  if (image.depth.empty())
    throw Error("the vision sensor keeps no depth image (its 'depth' setting is false)");
  lua_createtable(L, static_cast<int>(image.depth.size()), 0);
  for (size_t i = 0; i < image.depth.size(); ++i) {
    lua_pushnumber(L, image.depth[i]);
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
  PushResolution(L, s.lens);
  return 2;
}

int GetVisionSensorRes(lua_State* L) {
  PushResolution(L, SensorOf(L).lens);
  return 1;
}

// The chain's output: the sensor's own when its chain has elements, else
// an empty chain run now (packet 1 only, on the caller's copy).
const filters::FilterOutput& OutputOf(const VisionSensorRow& s, filters::FilterOutput* scratch) {
  if (!s.filters.empty()) return s.output;
  s.filters.Run(s.image, CameraModelOf(s.lens), scratch);
  return *scratch;
}

// result (1: the chain triggered: a blob, a point; else 0; -1 before the
// first image), then the packets: packet 1 (CoppeliaSim's 15 statistics),
// then one per element that gives values.
int ReadVisionSensor(lua_State* L) {
  const VisionSensorRow& s = SensorOf(L);
  if (s.rendered_step < 0) {
    lua_pushinteger(L, -1);
    return 1;
  }
  filters::FilterOutput scratch;
  const filters::FilterOutput& out = OutputOf(s, &scratch);
  lua_pushinteger(L, out.triggered ? 1 : 0);
  luaL_checkstack(L, static_cast<int>(out.packets.size()) + 2, "too many packets");
  // Packet 1 from the image now when the sense phase left it (module.cc).
  const std::vector<double> packet1 = out.packets[0].empty()
                                          ? filters::ImageStatistics(s.image, CameraModelOf(s.lens))
                                          : out.packets[0];
  PushNumberArray(L, packet1.data(), static_cast<int>(packet1.size()));
  for (size_t k = 1; k < out.packets.size(); ++k)
    PushNumberArray(L, out.packets[k].data(), static_cast<int>(out.packets[k].size()));
  return 1 + static_cast<int>(out.packets.size());
}

// The last blobs element's blobs, largest first: {pixels, color = {r, g, b},
// x, y (centroid, pixels from the top-left corner), u, v (0..1 from the
// bottom-left, CoppeliaSim's), box = {min_x, min_y, max_x, max_y},
// orientation (rad)}.
int GetVisionSensorBlobs(lua_State* L) {
  const VisionSensorRow& s = SensorOf(L);
  lua_createtable(L, static_cast<int>(s.output.blobs.size()), 0);
  if (s.rendered_step < 0 || s.filters.empty()) return 1;
  int index = 1;
  for (const filters::Blob& b : s.output.blobs) {
    lua_createtable(L, 0, 8);
    lua_pushinteger(L, b.pixels);
    lua_setfield(L, -2, "pixels");
    PushNumberArray(L, b.colour.data(), 3);
    lua_setfield(L, -2, "color");
    const std::pair<const char*, double> numbers[] = {
        {"x", b.x}, {"y", b.y}, {"u", b.u}, {"v", b.v}, {"orientation", b.orientation}};
    for (const auto& [name, value] : numbers) {
      lua_pushnumber(L, value);
      lua_setfield(L, -2, name);
    }
    const double box[4] = {static_cast<double>(b.min_x), static_cast<double>(b.min_y),
                           static_cast<double>(b.max_x), static_cast<double>(b.max_y)};
    PushNumberArray(L, box, 4);
    lua_setfield(L, -2, "box");
    lua_rawseti(L, -2, index++);
  }
  return 1;
}

int SetShapeColor(lua_State* L) {
  Scene& scene = *Context(L).scene;
  const ObjectId id = CheckObject(L, 1);
  if (scene.type(id) != ObjectType::kShape)
    throw Error("'" + scene.PathOf(id) + "' is a " + scene.type_name(scene.type(id)) +
                ", not a shape");
  CheckOwn(L, id, "shapes");
  // (h, {r, g, b}) or CoppeliaSim's (h, colorName, colorComponent, {r, g, b}).
  const int arg = lua_istable(L, 2) ? 2 : 4;
  ShapeData& shape = scene.mutable_shape(id);
  shape.color = ArgColor(L, arg);
  shape.mesh_colors = false;  // a mesh's materials give way
  return 0;
}

int GetShapeColor(lua_State* L) {
  Scene& scene = *Context(L).scene;
  const ObjectId id = CheckObject(L, 1);
  if (scene.type(id) != ObjectType::kShape)
    throw Error("'" + scene.PathOf(id) + "' is a " + scene.type_name(scene.type(id)) +
                ", not a shape");
  const Vec3& c = scene.shape(id).color;
  const double v[3] = {c.x, c.y, c.z};
  PushNumberArray(L, v, 3);
  return 1;
}

// CoppeliaSim's object parameters of vision sensors (and cameras):
// sim.getObjectFloatParam(h, sim.visionfloatparam_near_clipping | _far_clipping
// | _perspective_angle (rad, horizontal) | _ortho_size (m, the width)),
// sim.getObjectInt32Param(h, sim.visionintparam_resolution_x | _y).
constexpr int kNearClipping = 1000, kFarClipping = 1001, kResolutionX = 1002, kResolutionY = 1003,
              kPerspectiveAngle = 1004, kOrthoSize = 1005;

const Lens& LensOf(lua_State* L) {
  Scene& scene = *Context(L).scene;
  const ObjectId id = CheckObject(L, 1);
  const uint32_t slot = scene.SlotOf(id);
  ObjectType type;
  if (scene.FindType("vision_sensor", &type) && scene.type_at(slot) == type)
    return static_cast<Rows<VisionSensorRow>*>(scene.rows(type))->rows[scene.row_at(slot)].lens;
  if (scene.FindType("camera", &type) && scene.type_at(slot) == type)
    return static_cast<Rows<CameraRow>*>(scene.rows(type))->rows[scene.row_at(slot)].lens;
  throw Error("'" + scene.PathOf(id) + "' is a " + scene.type_name(scene.type_at(slot)) +
              ": swarmsim has object parameters of vision sensors and cameras only");
}

int GetObjectFloatParam(lua_State* L) {
  const Lens& lens = LensOf(L);
  switch (ArgInteger(L, 2)) {
    case kNearClipping: lua_pushnumber(L, lens.near); break;
    case kFarClipping: lua_pushnumber(L, lens.far); break;
    case kPerspectiveAngle: lua_pushnumber(L, lens.fov); break;
    case kOrthoSize: lua_pushnumber(L, lens.ortho_width); break;
    default: throw Error("unknown float parameter " + std::to_string(ArgInteger(L, 2)));
  }
  return 1;
}

int GetObjectInt32Param(lua_State* L) {
  const Lens& lens = LensOf(L);
  switch (ArgInteger(L, 2)) {
    case kResolutionX: lua_pushinteger(L, lens.width); break;
    case kResolutionY: lua_pushinteger(L, lens.height); break;
    default: throw Error("unknown integer parameter " + std::to_string(ArgInteger(L, 2)));
  }
  return 1;
}

LightRow& LightOf(lua_State* L) { return RowOf<LightRow>(L, 1, "light", "a light"); }

int SetLightOn(lua_State* L) {
  LightRow& light = LightOf(L);
  CheckOwn(L, CheckObject(L, 1), "lights");
  ArgType(L, 2, LUA_TBOOLEAN);
  light.on = lua_toboolean(L, 2) != 0;
  return 0;
}

int GetLightOn(lua_State* L) {
  lua_pushboolean(L, LightOf(L).on);
  return 1;
}

int SetLightColor(lua_State* L) {
  LightRow& light = LightOf(L);
  CheckOwn(L, CheckObject(L, 1), "lights");
  light.color = ArgColor(L, 2);
  return 0;
}

}  // namespace

void RegisterRenderingApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"getVisionSensorImg", Guarded<GetVisionSensorImg, "sim.getVisionSensorImg">},
      {"getVisionSensorDepth", Guarded<GetVisionSensorDepth, "sim.getVisionSensorDepth">},
      {"getVisionSensorRes", Guarded<GetVisionSensorRes, "sim.getVisionSensorRes">},
      {"readVisionSensor", Guarded<ReadVisionSensor, "sim.readVisionSensor">},
      {"getVisionSensorBlobs", Guarded<GetVisionSensorBlobs, "sim.getVisionSensorBlobs">},
      {"setShapeColor", Guarded<SetShapeColor, "sim.setShapeColor">},
      {"getShapeColor", Guarded<GetShapeColor, "sim.getShapeColor">},
      {"setLightOn", Guarded<SetLightOn, "sim.setLightOn">},
      {"getLightOn", Guarded<GetLightOn, "sim.getLightOn">},
      {"setLightColor", Guarded<SetLightColor, "sim.setLightColor">},
      {"getObjectFloatParam", Guarded<GetObjectFloatParam, "sim.getObjectFloatParam">},
      {"getObjectInt32Param", Guarded<GetObjectInt32Param, "sim.getObjectInt32Param">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
  const std::pair<const char*, int> constants[] = {
      {"visionfloatparam_near_clipping", kNearClipping},
      {"visionfloatparam_far_clipping", kFarClipping},
      {"visionintparam_resolution_x", kResolutionX},
      {"visionintparam_resolution_y", kResolutionY},
      {"visionfloatparam_perspective_angle", kPerspectiveAngle},
      {"visionfloatparam_ortho_size", kOrthoSize},
  };
  for (const auto& [name, value] : constants) {
    lua_pushinteger(L, value);
    lua_setfield(L, -2, name);
  }
}

}  // namespace swarmsim::rendering
