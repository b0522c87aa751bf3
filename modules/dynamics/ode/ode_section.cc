// The world file's ODE settings: `simulation: {physics: ode, ode: {solver:
// auto, iterations: 40, erp: 0.2, cfm: 1e-6, limit_erp: 0.2, limit_cfm:
// 1e-6}}`. worlds/README.md ("ODE settings") documents each key and what it
// trades (servo error and step time, measured).
#include <memory>
#include <string>

#include "framework/object_type.h"
#include "modules/dynamics/ode/ode_backend.h"

namespace swarmsim::ode {
namespace {

constexpr ObjectKey kKeys[] = {
    {"solver", "auto",
     "auto, world or quickstep: world is ODE's exact stepper (dWorldStep), quickstep its "
     "iterative one; auto takes world for worlds of at most 64 dynamic bodies, two thirds of "
     "them hanging from a fixed base (arms), quickstep otherwise"},
    {"iterations", "40", "quickstep's iterations per substep, 1..100000"},
    {"erp", "0.2", "error reduction parameter of joints and contacts, 0..1"},
    {"cfm", "1e-6", "constraint force mixing of joints, motors and contacts, 0..1"},
    {"limit_erp", "erp", "ERP of joint limits, 0..1 (a joint's own limit_erp wins)"},
    {"limit_cfm", "cfm", "CFM of joint limits, 0..1 (a joint's own limit_cfm wins)"},
};

constexpr NumberRule kCfm{"a number from 0 to 1", 0, 1};

std::shared_ptr<const DynamicsOptions> Read(const ObjectReader& r) {
  auto out = std::make_shared<WorldOptions>();
  Options& o = out->options;
  if (r.Has("solver")) {
    const std::string solver = r.Choice("solver", {"auto", "world", "quickstep"});
    o.solver = solver == "world"       ? Solver::kWorld
               : solver == "quickstep" ? Solver::kQuickStep
                                       : Solver::kAuto;
  }
  if (r.Has("iterations")) o.iterations = static_cast<int>(r.Integer("iterations", 1, 100000));
  if (r.Has("erp")) o.erp = r.Number("erp", kFraction);
  if (r.Has("cfm")) o.cfm = r.Number("cfm", kCfm);
  if (r.Has("limit_erp")) o.limit_erp = r.Number("limit_erp", kFraction);
  if (r.Has("limit_cfm")) o.limit_cfm = r.Number("limit_cfm", kCfm);
  return out;
}

}  // namespace

DynamicsSection Section() { return {.keys = kKeys, .read = Read}; }

}  // namespace swarmsim::ode
