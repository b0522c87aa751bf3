// sim.* vision sensors, shape colours and lights (the Lua area of the
// vision_sensor and light types):
//   sim.getVisionSensorImg(h) -> bytes (RGB, rows top to bottom), {width, height}
//   sim.getVisionSensorDepth(h) -> {d, ...} (m along the view axis; far where
//     nothing), {width, height}
//   sim.getVisionSensorRes(h) -> {width, height}
//   sim.readVisionSensor(h) -> result, packet1 (CoppeliaSim's 15 values: min,
//     max and average of intensity, red, green, blue and depth), ...
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

Vec3 ArgColor(lua_State* L, int arg) {
  ArgType(L, arg, LUA_TTABLE);
  double rgb[3];
  for (int i = 0; i < 3; ++i) {
    lua_rawgeti(L, arg, i + 1);
    int ok = 0;
    rgb[i] = lua_tonumberx(L, -1, &ok);
    lua_pop(L, 1);
    if (!ok || !(rgb[i] >= 0 && rgb[i] <= 1))
      throw Error("the colour must be {r, g, b} with each component between 0 and 1");
  }
  return {rgb[0], rgb[1], rgb[2]};
}

void PushResolution(lua_State* L, const Lens& lens) {
  lua_createtable(L, 2, 0);
  lua_pushinteger(L, lens.width);
  lua_rawseti(L, -2, 1);
  lua_pushinteger(L, lens.height);
  lua_rawseti(L, -2, 2);
}

const Image& ImageOf(const VisionSensorRow& s) {
  if (s.rendered_step < 0) throw Error("the vision sensor has not rendered an image yet");
  return s.image;
}

int GetVisionSensorImg(lua_State* L) {
  const VisionSensorRow& s = SensorOf(L);
  const Image& image = ImageOf(s);
  lua_pushlstring(L, reinterpret_cast<const char*>(image.rgb.data()), image.rgb.size());
  PushResolution(L, s.lens);
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

// CoppeliaSim's first packet: min, max, average of intensity, red, green,
// blue, depth (0..1 as CoppeliaSim; depth normalised to near..far).
void PushPacket1(lua_State* L, const VisionSensorRow& s) {
  const Image& image = s.image;
  double lo[5], hi[5], sum[5];
  std::fill(lo, lo + 5, INFINITY);
  std::fill(hi, hi + 5, -INFINITY);
  std::fill(sum, sum + 5, 0.0);
  const size_t n = static_cast<size_t>(image.width) * static_cast<size_t>(image.height);
  for (size_t i = 0; i < n; ++i) {
    const double r = image.rgb[3 * i] / 255.0, g = image.rgb[3 * i + 1] / 255.0,
                 b = image.rgb[3 * i + 2] / 255.0;
    const double d =
        image.depth.empty() ? 1.0 : (image.depth[i] - s.lens.near) / (s.lens.far - s.lens.near);
    const double v[5] = {(r + g + b) / 3, r, g, b, d};
    for (int k = 0; k < 5; ++k) {
      lo[k] = std::min(lo[k], v[k]);
      hi[k] = std::max(hi[k], v[k]);
      sum[k] += v[k];
    }
  }
  lua_createtable(L, 15, 0);
  int index = 1;
  for (int k = 0; k < 5; ++k) {
    const double values[3] = {lo[k], hi[k], n > 0 ? sum[k] / static_cast<double>(n) : 0};
    for (double v : values) {
      lua_pushnumber(L, n > 0 ? v : 0);
      lua_rawseti(L, -2, index++);
    }
  }
}

int ReadVisionSensor(lua_State* L) {
  const VisionSensorRow& s = SensorOf(L);
  if (s.rendered_step < 0) {
    lua_pushinteger(L, -1);
    return 1;
  }
  lua_pushinteger(L, 0);
  PushPacket1(L, s);
  return 2;
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
