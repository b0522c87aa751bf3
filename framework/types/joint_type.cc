// joint: a kinematic pair that moves its children about (revolute) or along
// (prismatic) its own z axis, or both coupled (screw), or turns them freely
// (spherical), or holds them (fixed); passive, velocity-, position- or
// force-driven, or dependent on another joint (master, factor, offset).
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "framework/dependent_joints.h"
#include "framework/object_type.h"
#include "framework/scene.h"
#include "framework/sensor_noise.h"
#include "framework/state_hash.h"
#include "framework/types/core_types.h"
#include "framework/world_state.h"

namespace swarmsim {

// Its Lua API area (framework/lua_api_*.cc).
void RegisterJointsApi(lua_State* L);

namespace {

constexpr ObjectKey kKeys[] = {
    {"joint", "revolute",
     "revolute, prismatic, screw (kinematic), spherical (ball; ode only simulates it) or fixed"},
    {"pitch", "none", "screw joints (required): m of travel along z per rad, finite, nonzero"},
    {"mode", "velocity", "passive, velocity, position or force (applies target_force; ode only)"},
    {"max_force", "10", "N or N m, > 0"},
    {"max_velocity", "10", "rad/s or m/s, > 0 (position mode)"},
    {"target_velocity", "0", "rad/s or m/s, initial target"},
    {"target_position", "0", "rad or m, initial target"},
    {"initial_position", "0", "rad or m, the joint's position at the start"},
    {"target_force", "0", "N or N m, force mode"},
    {"damping", "0",
     "N m s/rad or N s/m, >= 0: a viscous torque or force -damping * velocity (ode)"},
    {"limits", "none", "[min, max], rad or m: ODE stops, and IK keeps solutions inside"},
    {"limit_erp", "simulation.ode's",
     "0..1, ode: how much of a limit's violation is corrected each substep (1: all)"},
    {"limit_cfm", "simulation.ode's",
     "0..1, ode: the limits' softness (0: hard; larger: they give under load)"},
    {"master", "none", "path of the joint this one follows: q = offset + factor * q_master"},
    {"factor", "1", "dependent joints: factor of the master's position"},
    {"offset", "0", "dependent joints: rad or m added"},
    {"ik", "active", "active (IK groups move it) or frozen (IK keeps its value)"},
    {"velocity_noise", "0",
     "rad/s or m/s, >= 0, velocity mode: std dev of Gaussian noise on the speed driven"},
    {"velocity_noise_uniform", "0",
     "rad/s or m/s, >= 0, velocity mode: half width of uniform noise on the speed driven"},
    {"velocity_noise_factor", "0",
     ">= 0, velocity mode: std dev of a Gaussian factor about 1 multiplying the speed driven"},
    {"velocity_failure_probability", "0",
     "0..1, velocity mode: chance that the motor drives nothing in a step"},
    {"slip", "0", "0..1, velocity mode: fraction of the target speed lost (wheel slip)"},
};

std::unique_ptr<RowTable> MakeRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<JointData>>();
}

// Prismatic: lengths x s, forces (N) x s^3; revolute and others: angles
// unchanged, torques (N m) x s^4. The settings scaled are this copy's own
// (copy on write): the other copies keep theirs.
void Scale(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  JointData& j = *static_cast<JointData*>(row);
  JointSettings& settings = j.settings.Edit();
  const double s3 = s * s * s, s4 = s3 * s;
  if (settings.type == JointType::kPrismatic) {
    for (double* v :
         {&j.position, &j.velocity, &j.target_velocity, &j.target_position, &j.drive_velocity,
          &settings.max_velocity, &settings.min_position, &settings.max_position,
          &settings.velocity_noise.gaussian, &settings.velocity_noise.uniform})
      *v *= s;
    settings.max_force *= s3;
    j.target_force *= s3;
    settings.damping *= s * s;  // N s/m
  } else {
    if (settings.type == JointType::kScrew) settings.pitch *= s;  // m per rad
    settings.max_force *= s4;
    j.target_force *= s4;
    settings.damping *= s4;  // N m s/rad
  }
  // A prismatic joint's offset is a length (the factor's units depend on
  // the master's kind and stay as they are).
  if (settings.depends && settings.type == JointType::kPrismatic) {
    auto d = std::make_shared<JointDependency>(*settings.depends);
    d->offset *= s;
    settings.depends = std::move(d);
  }
}

// State only: the settings are the model's.
void Hash(const Scene& scene, ObjectType, StateHasher* h) {
  for (size_t r = 0; r < scene.joints().size(); ++r) {
    const JointData& j = scene.joints()[r];
    h->AddValue(scene.joint_owners()[r]);
    h->AddValue(j.position);
    h->AddValue(j.velocity);
    h->AddValue(j.target_velocity);
    h->AddValue(j.target_position);
    if (j.ik_frozen) h->AddValue(j.ik_frozen);  // (only when set: older hashes stay)
  }
}

// Snapshots (framework/world_state.h): the state, settings stay the model's.
void Save(const Scene& scene, ObjectType, StateWriter* out) {
  for (const JointData& j : scene.joints()) {
    for (const double v : {j.position, j.velocity, j.target_velocity, j.drive_velocity,
                           j.target_position, j.target_force})
      out->Put(v);
    out->Put(j.ball);
    out->Put<uint8_t>(j.simulated);
    out->Put<uint8_t>(j.ik_frozen);
  }
}

void Load(Scene* scene, ObjectType, StateReader* in) {
  for (JointData& j : scene->joints()) {
    for (double* v : {&j.position, &j.velocity, &j.target_velocity, &j.drive_velocity,
                      &j.target_position, &j.target_force})
      *v = in->Get<double>();
    j.ball = in->Get<Quat>();
    j.simulated = in->GetBool();
    j.ik_frozen = in->GetBool();
  }
}

void Read(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  JointData& j = *static_cast<JointData*>(row);
  JointSettings& settings = j.settings.Edit();  // this row's own (a fresh row's, when loading)
  if (r.Has("joint")) {
    const std::string type =
        r.Choice("joint", {"revolute", "prismatic", "screw", "spherical", "fixed"});
    settings.type = type == "revolute"    ? JointType::kRevolute
                    : type == "prismatic" ? JointType::kPrismatic
                    : type == "screw"     ? JointType::kScrew
                    : type == "spherical" ? JointType::kSpherical
                                          : JointType::kFixed;
  }
  if (settings.type == JointType::kScrew) {
    if (!r.Has("pitch"))
      r.FailAtKey("joint", "a screw joint needs 'pitch' (m of travel per rad, nonzero)");
    settings.pitch = r.Number("pitch", kAnyNumber);
    if (!std::isfinite(settings.pitch) || settings.pitch == 0)
      r.Fail("pitch", "'pitch' must be a finite, nonzero number of m per rad");
  } else if (r.Has("pitch")) {
    r.FailAtKey("pitch", "'pitch' is for screw joints (joint: screw)");
  }
  if (r.Has("master")) {
    auto d = std::make_shared<JointDependency>();
    d->master = r.String("master", true);
    if (d->master.empty() || (d->master[0] != '/' && d->master[0] != ':' && d->master[0] != '.'))
      r.Fail("master", "'" + d->master +
                           "' is not a joint path: start with '/' (absolute), ':' (this model) "
                           "or './' (below this joint)");
    if (r.Has("factor")) d->factor = r.Number("factor", kAnyNumber);
    if (r.Has("offset")) d->offset = r.Number("offset", kAnyNumber);
    d->where = r.Where("master");
    settings.depends = std::move(d);
  } else {
    for (const char* key : {"factor", "offset"})
      if (r.Has(key))
        r.FailAtKey(key, std::string("'") + key + "' is for dependent joints: add 'master'");
  }
  if (r.Has("mode")) {
    const std::string mode = r.Choice("mode", {"passive", "velocity", "position", "force"});
    settings.mode = mode == "passive"    ? JointMode::kPassive
                    : mode == "velocity" ? JointMode::kVelocity
                    : mode == "position" ? JointMode::kPosition
                                         : JointMode::kForce;
  }
  if (r.Has("ik")) j.ik_frozen = r.Choice("ik", {"active", "frozen"}) == "frozen";
  if (r.Has("target_force")) j.target_force = r.Number("target_force", kAnyNumber);
  if (r.Has("damping")) settings.damping = r.Number("damping", kNonNegative);
  if (r.Has("limits")) {
    // [min, max] in rad or m, like initial_position.
    const std::vector<double> v = r.Numbers("limits", 2, 2, kAnyNumber);
    if (!(v[0] <= v[1])) r.Fail("limits", "'limits' must be [min, max] with min <= max");
    settings.min_position = v[0];
    settings.max_position = v[1];
  }
  if (r.Has("limit_erp")) settings.limit_erp = r.Number("limit_erp", kFraction);
  if (r.Has("limit_cfm")) settings.limit_cfm = r.Number("limit_cfm", kFraction);
  ReadNoise(r, "velocity_", 1e6, &settings.velocity_noise);
  if (r.Has("velocity_noise_factor"))
    settings.velocity_noise_factor =
        r.Number("velocity_noise_factor", {"a number from 0 to 10", 0, 10});
  if (r.Has("slip")) settings.slip = r.Number("slip", kFraction);
  if (settings.drive_noisy() && settings.mode != JointMode::kVelocity)
    for (const char* key : {"velocity_noise", "velocity_noise_uniform", "velocity_noise_factor",
                            "velocity_failure_probability", "slip"})
      if (r.Has(key))
        r.FailAtKey(key, std::string("'") + key + "' is for velocity-mode joints (mode: velocity)");
  if (r.Has("max_force")) settings.max_force = r.Number("max_force", kPositive);
  if (r.Has("max_velocity")) settings.max_velocity = r.Number("max_velocity", kPositive);
  if (r.Has("target_velocity")) j.target_velocity = r.Number("target_velocity", kAnyNumber);
  if (r.Has("target_position")) j.target_position = r.Number("target_position", kAnyNumber);
  if (r.Has("initial_position")) {
    j.position = r.Number("initial_position", kAnyNumber);
    // A joint placed past its own stops: ODE snapped it back with a jolt on
    // the first step, the other backends kept it there.
    if (r.Has("limits") &&
        !(j.position >= settings.min_position && j.position <= settings.max_position)) {
      char text[120];
      std::snprintf(text, sizeof text, "'initial_position' %.9g is outside 'limits' [%.9g, %.9g]",
                    j.position, settings.min_position, settings.max_position);
      r.Fail("initial_position", text);
    }
  }
}

// A dependent joint's master is a joint, and masters never lead back to it.
void Check(const Scene& scene, ObjectId id, const void*) { CheckJointDependency(scene, id); }

}  // namespace

constinit const ObjectTypeDescriptor kJointType{
    .name = "joint",
    .description =
        "a revolute, prismatic, screw, spherical or fixed joint; passive, driven or dependent",
    .make_rows = MakeRows,
    .scale_row = Scale,
    .hash_rows = Hash,
    .keys = kKeys,
    .read = Read,
    .check = Check,
    .register_lua = RegisterJointsApi,
    .save_rows = Save,
    .load_rows = Load,
};

}  // namespace swarmsim
