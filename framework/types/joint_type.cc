// joint: a kinematic pair that moves its children about (revolute) or along
// (prismatic) its own z axis, or turns them freely (spherical), or holds
// them (fixed); passive, velocity-, position- or force-driven.
#include "framework/object_type.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "framework/types/core_types.h"

namespace swarmsim {

// Its Lua API area (framework/lua_api_*.cc).
void RegisterJointsApi(lua_State* L);

namespace {

constexpr ObjectKey kKeys[] = {
    {"joint", "revolute", "revolute, prismatic, spherical (ball; ode only simulates it) or fixed"},
    {"mode", "velocity", "passive, velocity, position or force (applies target_force; ode only)"},
    {"max_force", "10", "N or N m, > 0"},
    {"max_velocity", "10", "rad/s or m/s, > 0 (position mode)"},
    {"target_velocity", "0", "rad/s or m/s, initial target"},
    {"target_position", "0", "rad or m, initial target"},
    {"initial_position", "0", "rad or m, the joint's position at the start"},
    {"target_force", "0", "N or N m, force mode"},
    {"limits", "none", "[min, max], rad or m: ODE stops, and IK keeps solutions inside"},
};

std::unique_ptr<RowTable> MakeRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<JointData>>();
}

// Prismatic: lengths x s, forces (N) x s^3; revolute and others: angles
// unchanged, torques (N m) x s^4.
void Scale(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  JointData& j = *static_cast<JointData*>(row);
  const double s3 = s * s * s, s4 = s3 * s;
  if (j.type == JointType::kPrismatic) {
    for (double* v : {&j.position, &j.velocity, &j.target_velocity, &j.target_position,
                      &j.max_velocity, &j.min_position, &j.max_position})
      *v *= s;
    j.max_force *= s3;
    j.target_force *= s3;
  } else {
    j.max_force *= s4;
    j.target_force *= s4;
  }
}

void Hash(const Scene& scene, ObjectType, StateHasher* h) {
  for (size_t r = 0; r < scene.joints().size(); ++r) {
    const JointData& j = scene.joints()[r];
    h->AddValue(scene.joint_owners()[r]);
    h->AddValue(j.position);
    h->AddValue(j.velocity);
    h->AddValue(j.target_velocity);
    h->AddValue(j.target_position);
  }
}

void Read(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  JointData& j = *static_cast<JointData*>(row);
  if (r.Has("joint")) {
    const std::string type = r.Choice("joint", {"revolute", "prismatic", "spherical", "fixed"});
    j.type = type == "revolute"    ? JointType::kRevolute
             : type == "prismatic" ? JointType::kPrismatic
             : type == "spherical" ? JointType::kSpherical
                                   : JointType::kFixed;
  }
  if (r.Has("mode")) {
    const std::string mode = r.Choice("mode", {"passive", "velocity", "position", "force"});
    j.mode = mode == "passive"    ? JointMode::kPassive
             : mode == "velocity" ? JointMode::kVelocity
             : mode == "position" ? JointMode::kPosition
                                  : JointMode::kForce;
  }
  if (r.Has("target_force")) j.target_force = r.Number("target_force", kAnyNumber);
  if (r.Has("limits")) {
    // [min, max] in rad or m, like initial_position.
    const std::vector<double> v = r.Numbers("limits", 2, 2, kAnyNumber);
    if (!(v[0] <= v[1])) r.Fail("limits", "'limits' must be [min, max] with min <= max");
    j.min_position = v[0];
    j.max_position = v[1];
  }
  if (r.Has("max_force")) j.max_force = r.Number("max_force", kPositive);
  if (r.Has("max_velocity")) j.max_velocity = r.Number("max_velocity", kPositive);
  if (r.Has("target_velocity")) j.target_velocity = r.Number("target_velocity", kAnyNumber);
  if (r.Has("target_position")) j.target_position = r.Number("target_position", kAnyNumber);
  if (r.Has("initial_position")) j.position = r.Number("initial_position", kAnyNumber);
}

}  // namespace

constinit const ObjectTypeDescriptor kJointType{
    .name = "joint",
    .description = "a revolute, prismatic, spherical or fixed joint; passive or driven",
    .make_rows = MakeRows,
    .scale_row = Scale,
    .hash_rows = Hash,
    .keys = kKeys,
    .read = Read,
    .register_lua = RegisterJointsApi,
};

}  // namespace swarmsim
