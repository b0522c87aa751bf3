#include "modules/dynamics/kinematic/kinematic_backend.h"

namespace swarmsim::kinematic {

namespace {

class KinematicBackend final : public DynamicsBackend {
 public:
  void Build(const Scene& /*scene*/, const DynamicsSettings& /*settings*/) override {}
  void Step(Scene* /*scene*/, double /*dt*/, int /*substeps*/) override {}
  int body_count() const override { return 0; }
};

}  // namespace

swarmsim::ModuleInfo ModuleInfo() {
  return {"dynamics", "kinematic", "1.0",
          "no dynamics: objects move only by scripts, IK and joint targets"};
}

std::unique_ptr<DynamicsBackend> MakeBackend() { return std::make_unique<KinematicBackend>(); }

}  // namespace swarmsim::kinematic
