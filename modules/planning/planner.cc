// The planner on OMPL, inside the OMPL module (ompl_module.h): Plan
// (planner.h) behind plan.cc.
#include <ompl/base/PlannerTerminationCondition.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/StateSampler.h>
#include <ompl/base/spaces/ReedsSheppStateSpace.h>
#include <ompl/base/spaces/SE2StateSpace.h>
#include <ompl/base/spaces/SE3StateSpace.h>
#include <ompl/datastructures/NearestNeighborsGNATNoThreadSafety.h>
#include <ompl/datastructures/NearestNeighborsSqrtApprox.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/planners/rrt/RRT.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "framework/random.h"
#include "modules/planning/ompl_module.h"

namespace swarmsim::planning {

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace {

using Se2State = ob::SE2StateSpace::StateType;
using Se3State = ob::SE3StateSpace::StateType;

// An angle in [-pi, pi), where OMPL's SO2 bounds hold it (pi itself is out:
// a goal heading of exactly pi was never reached).
double WrapAngle(double a) {
  const double w = std::remainder(a, 2 * M_PI);
  return w >= M_PI ? w - 2 * M_PI : w;
}

// Every draw of the planner: uniform states in the bounds from the
// request's stream (OMPL's own samplers seed themselves from a process-wide
// generator in creation order, which threads race for).
class SeededSampler : public ob::StateSampler {
 public:
  SeededSampler(const ob::StateSpace* space, Rng* rng, bool planar, const Vec3& lo, const Vec3& hi)
      : ob::StateSampler(space), rng_(rng), planar_(planar), lo_(lo), hi_(hi) {}

  void sampleUniform(ob::State* state) override {
    if (planar_) {
      auto* s = state->as<Se2State>();
      s->setXY(rng_->Uniform(lo_.x, hi_.x), rng_->Uniform(lo_.y, hi_.y));
      s->setYaw(rng_->Uniform(-M_PI, M_PI));
      return;
    }
    auto* s = state->as<Se3State>();
    s->setXYZ(rng_->Uniform(lo_.x, hi_.x), rng_->Uniform(lo_.y, hi_.y),
              rng_->Uniform(lo_.z, hi_.z));
    // A uniform rotation (Shoemake).
    const double u1 = rng_->Uniform(), u2 = rng_->Uniform(0, 2 * M_PI),
                 u3 = rng_->Uniform(0, 2 * M_PI);
    const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
    ob::SO3StateSpace::StateType& r = s->rotation();
    r.x = a * std::sin(u2);
    r.y = a * std::cos(u2);
    r.z = b * std::sin(u3);
    r.w = b * std::cos(u3);
  }

  void sampleUniformNear(ob::State* state, const ob::State* near, double distance) override {
    if (planar_) {
      const auto* n = near->as<Se2State>();
      auto* s = state->as<Se2State>();
      s->setXY(std::clamp(n->getX() + rng_->Uniform(-distance, distance), lo_.x, hi_.x),
               std::clamp(n->getY() + rng_->Uniform(-distance, distance), lo_.y, hi_.y));
      s->setYaw(WrapAngle(n->getYaw() + rng_->Uniform(-distance, distance)));
      return;
    }
    const auto* n = near->as<Se3State>();
    auto* s = state->as<Se3State>();
    s->setXYZ(std::clamp(n->getX() + rng_->Uniform(-distance, distance), lo_.x, hi_.x),
              std::clamp(n->getY() + rng_->Uniform(-distance, distance), lo_.y, hi_.y),
              std::clamp(n->getZ() + rng_->Uniform(-distance, distance), lo_.z, hi_.z));
    s->rotation().x = n->rotation().x;
    s->rotation().y = n->rotation().y;
    s->rotation().z = n->rotation().z;
    s->rotation().w = n->rotation().w;
  }

  void sampleGaussian(ob::State* state, const ob::State* mean, double stddev) override {
    sampleUniformNear(state, mean, stddev);
  }

 private:
  Rng* rng_;
  bool planar_;
  Vec3 lo_, hi_;
};

// Dubins curves (forward-only cars), our own: Debian's OMPL 1.5.2 is built
// with assertions on, and its DubinsStateSpace takes a float square root
// (sqrtf) whose rounding trips its own assertion between states more than
// about 30 turning radii apart, aborting the process. Same words and
// formulas (Shkel & Lumelsky, as in A. Walker's dubins.c), in double.
class DubinsSpace : public ob::SE2StateSpace {
 public:
  explicit DubinsSpace(double radius) : radius_(radius) { setName("Dubins" + getName()); }
  bool isMetricSpace() const override { return false; }
  bool hasSymmetricDistance() const override { return false; }
  bool hasSymmetricInterpolate() const override { return false; }

  double distance(const ob::State* a, const ob::State* b) const override {
    const Word w = Shortest(a, b);
    return (w.length[0] + w.length[1] + w.length[2]) * radius_;
  }

  void interpolate(const ob::State* from, const ob::State* to, double t,
                   ob::State* state) const override {
    const Word w = Shortest(from, to);
    const auto* s = from->as<Se2State>();
    double x = s->getX(), y = s->getY(), h = s->getYaw();
    double left = std::clamp(t, 0.0, 1.0) * (w.length[0] + w.length[1] + w.length[2]);
    for (int i = 0; i < 3 && left > 0; ++i) {
      const double a = std::min(left, w.length[i]);
      left -= a;
      const double r = radius_;
      switch (w.turn[i]) {
        case 'L':
          x += r * (std::sin(h + a) - std::sin(h));
          y += r * (std::cos(h) - std::cos(h + a));
          h += a;
          break;
        case 'R':
          x += r * (std::sin(h) - std::sin(h - a));
          y += r * (std::cos(h - a) - std::cos(h));
          h -= a;
          break;
        default: x += r * a * std::cos(h); y += r * a * std::sin(h);
      }
    }
    auto* out = state->as<Se2State>();
    if (t >= 1) {  // exactly the end state, not its rounding
      copyState(state, to);
      return;
    }
    out->setXY(x, y);
    out->setYaw(WrapAngle(h));
  }

 private:
  struct Word {
    char turn[3] = {'L', 'S', 'L'};
    double length[3] = {INFINITY, 0, 0};  // per unit radius
  };

  // Into [0, 2 pi); within 1e-10 of a full turn (rounding) is 0.
  static double Mod2Pi(double a) {
    double m = std::fmod(a, 2 * M_PI);
    if (m < 0) m += 2 * M_PI;
    return m > 2 * M_PI - 1e-10 || m < 1e-10 ? 0 : m;
  }

  Word Shortest(const ob::State* a, const ob::State* b) const {
    const auto *s1 = a->as<Se2State>(), *s2 = b->as<Se2State>();
    const double dx = s2->getX() - s1->getX(), dy = s2->getY() - s1->getY();
    const double d = std::hypot(dx, dy) / radius_;
    const double th = d > 0 ? std::atan2(dy, dx) : 0;
    const double alpha = Mod2Pi(s1->getYaw() - th), beta = Mod2Pi(s2->getYaw() - th);
    const double sa = std::sin(alpha), sb = std::sin(beta), ca = std::cos(alpha),
                 cb = std::cos(beta), c_ab = std::cos(alpha - beta), d2 = d * d;
    Word best;
    if (d < 1e-9 && std::abs(std::remainder(alpha - beta, 2 * M_PI)) < 1e-9) {
      best.length[0] = 0;  // the same state (up to rounding): nothing to drive
      return best;
    }
    const auto offer = [&best](const char* turns, double t, double p, double q) {
      if (t + p + q < best.length[0] + best.length[1] + best.length[2]) {
        best = {{turns[0], turns[1], turns[2]}, {t, p, q}};
      }
    };
    double p2 = 2 + d2 - 2 * c_ab + 2 * d * (sa - sb);  // LSL
    if (p2 >= 0) {
      const double th1 = std::atan2(cb - ca, d + sa - sb);
      offer("LSL", Mod2Pi(th1 - alpha), std::sqrt(p2), Mod2Pi(beta - th1));
    }
    p2 = 2 + d2 - 2 * c_ab + 2 * d * (sb - sa);  // RSR
    if (p2 >= 0) {
      const double th1 = std::atan2(ca - cb, d - sa + sb);
      offer("RSR", Mod2Pi(alpha - th1), std::sqrt(p2), Mod2Pi(th1 - beta));
    }
    p2 = -2 + d2 + 2 * c_ab + 2 * d * (sa + sb);  // LSR
    if (p2 >= 0) {
      const double p = std::sqrt(p2);
      const double th2 = std::atan2(-ca - cb, d + sa + sb) - std::atan2(-2.0, p);
      offer("LSR", Mod2Pi(th2 - alpha), p, Mod2Pi(th2 - beta));
    }
    p2 = -2 + d2 + 2 * c_ab - 2 * d * (sa + sb);  // RSL
    if (p2 >= 0) {
      const double p = std::sqrt(p2);
      const double th2 = std::atan2(ca + cb, d - sa - sb) - std::atan2(2.0, p);
      offer("RSL", Mod2Pi(alpha - th2), p, Mod2Pi(beta - th2));
    }
    double c = (6 - d2 + 2 * c_ab + 2 * d * (sa - sb)) / 8;  // RLR
    if (std::abs(c) <= 1) {
      const double phi = std::atan2(ca - cb, d - sa + sb);
      const double p = Mod2Pi(2 * M_PI - std::acos(c));
      const double t = Mod2Pi(alpha - phi + Mod2Pi(p / 2));
      offer("RLR", t, p, Mod2Pi(alpha - beta - t + Mod2Pi(p)));
    }
    c = (6 - d2 + 2 * c_ab + 2 * d * (sb - sa)) / 8;  // LRL
    if (std::abs(c) <= 1) {
      const double phi = std::atan2(ca - cb, d + sa - sb);
      const double p = Mod2Pi(2 * M_PI - std::acos(c));
      const double t = Mod2Pi(-alpha - phi + p / 2);
      offer("LRL", t, p, Mod2Pi(Mod2Pi(beta) - alpha - t + Mod2Pi(p)));
    }
    return best;
  }

  double radius_;
};

// RRT-Connect with its own RNG seeded, and how far each tree spread.
class SeededRrtConnect : public og::RRTConnect {
 public:
  using og::RRTConnect::RRTConnect;
  void Seed(uint32_t seed) { rng_.setLocalSeed(seed); }
  // The farthest (xy) any state of the start (or goal) tree got from its root.
  double Reach(bool goal_tree, bool planar) const {
    std::vector<Motion*> motions;
    (goal_tree ? tGoal_ : tStart_)->list(motions);
    double reach = 0;
    for (const Motion* m : motions) {
      double dx, dy;
      if (planar) {
        const auto *a = m->state->as<Se2State>(), *b = m->root->as<Se2State>();
        dx = a->getX() - b->getX();
        dy = a->getY() - b->getY();
      } else {
        const auto *a = m->state->as<Se3State>(), *b = m->root->as<Se3State>();
        dx = a->getX() - b->getX();
        dy = a->getY() - b->getY();
      }
      reach = std::max(reach, std::hypot(dx, dy));
    }
    return reach;
  }
};

class SeededRrt : public og::RRT {
 public:
  using og::RRT::RRT;
  void Seed(uint32_t seed) { rng_.setLocalSeed(seed); }
};

Pose ToPose(const ob::State* state, bool planar, double z) {
  if (planar) {
    const auto* s = state->as<Se2State>();
    return {{s->getX(), s->getY(), z}, Quat::FromYaw(s->getYaw())};
  }
  const auto* s = state->as<Se3State>();
  const auto& r = s->rotation();
  return {{s->getX(), s->getY(), s->getZ()}, Quat{r.w, r.x, r.y, r.z}.Normalized()};
}

void FromPose(const Pose& X, bool planar, ob::State* state) {
  if (planar) {
    auto* s = state->as<Se2State>();
    s->setXY(X.p.x, X.p.y);
    s->setYaw(WrapAngle(X.q.Yaw()));
    return;
  }
  auto* s = state->as<Se3State>();
  s->setXYZ(X.p.x, X.p.y, X.p.z);
  const Quat q = X.q.Normalized();
  s->rotation().x = q.x;
  s->rotation().y = q.y;
  s->rotation().z = q.z;
  s->rotation().w = q.w;
}

ob::StateSpacePtr MakeSpace(const PlanRequest& r) {
  ob::StateSpacePtr space;
  switch (r.space) {
    case Space::kSe2: space = std::make_shared<ob::SE2StateSpace>(); break;
    case Space::kDubins: space = std::make_shared<DubinsSpace>(r.turning_radius); break;
    case Space::kReedsShepp:
      space = std::make_shared<ob::ReedsSheppStateSpace>(r.turning_radius);
      break;
    case Space::kSe3: space = std::make_shared<ob::SE3StateSpace>(); break;
  }
  if (IsPlanar(r.space)) {
    ob::RealVectorBounds bounds(2);
    bounds.setLow(0, r.lo.x);
    bounds.setHigh(0, r.hi.x);
    bounds.setLow(1, r.lo.y);
    bounds.setHigh(1, r.hi.y);
    space->as<ob::SE2StateSpace>()->setBounds(bounds);
  } else {
    ob::RealVectorBounds bounds(3);
    const double lo[3] = {r.lo.x, r.lo.y, r.lo.z}, hi[3] = {r.hi.x, r.hi.y, r.hi.z};
    for (unsigned i = 0; i < 3; ++i) {
      bounds.setLow(i, lo[i]);
      bounds.setHigh(i, hi[i]);
    }
    space->as<ob::SE3StateSpace>()->setBounds(bounds);
  }
  return space;
}

// One search: the planner's tree(s) from start to goal within `budget`
// iterations. Returns the exact solution's states (empty: none) and, for
// RRT-Connect, how far each tree spread.
struct Search {
  std::vector<Pose> states;
  double start_reach = 0, goal_reach = 0;
  int64_t iterations = 0;
};

Search RunSearch(const PlanRequest& r, Space space_kind, const ValidityFn& valid, int64_t budget,
                 std::vector<Pose>* waypoints, std::vector<Pose>* dense) {
  PlanRequest request = r;
  request.space = space_kind;
  const bool planar = IsPlanar(space_kind);
  Rng rng(r.seed, static_cast<uint64_t>(space_kind));
  ob::StateSpacePtr space = MakeSpace(request);
  space->setStateSamplerAllocator([&rng, planar, &r](const ob::StateSpace* s) {
    return std::make_shared<SeededSampler>(s, &rng, planar, r.lo, r.hi);
  });
  auto si = std::make_shared<ob::SpaceInformation>(space);
  const double z = r.start.p.z;
  const ob::SpaceInformation* raw = si.get();
  si->setStateValidityChecker([raw, planar, z, &valid](const ob::State* s) {
    return raw->satisfiesBounds(s) && valid(ToPose(s, planar, z));
  });
  si->setStateValidityCheckingResolution(
      std::min(0.5, r.resolution / std::max(space->getMaximumExtent(), 1e-9)));
  si->setup();

  ob::ScopedState<> start(space), goal(space);
  FromPose(r.start, planar, start.get());
  FromPose(r.goal, planar, goal.get());
  auto pdef = std::make_shared<ob::ProblemDefinition>(si);
  pdef->setStartAndGoalStates(start, goal, 1e-6);

  Search out;
  std::shared_ptr<SeededRrtConnect> connect;
  ob::PlannerPtr planner;
  if (space_kind == Space::kSe2 || space_kind == Space::kSe3) {
    connect = std::make_shared<SeededRrtConnect>(si);
    connect->Seed(static_cast<uint32_t>(rng.NextU64() | 1));
    connect->setNearestNeighbors<ompl::NearestNeighborsGNATNoThreadSafety>();
    planner = connect;
  } else {
    auto rrt = std::make_shared<SeededRrt>(si);
    rrt->Seed(static_cast<uint32_t>(rng.NextU64() | 1));
    rrt->setNearestNeighbors<ompl::NearestNeighborsSqrtApprox>();
    rrt->setGoalBias(0.05);
    planner = rrt;
  }
  planner->setProblemDefinition(pdef);
  planner->setup();
  // The time limit as a budget of termination checks (one per iteration).
  int64_t checks = 0;
  const ob::PlannerTerminationCondition ptc([&checks, budget] { return ++checks > budget; });
  const ob::PlannerStatus status = planner->solve(ptc);
  out.iterations = std::min(checks, budget);
  if (connect) {
    out.start_reach = connect->Reach(false, planar);
    out.goal_reach = connect->Reach(true, planar);
  }
  if (status != ob::PlannerStatus::EXACT_SOLUTION) return out;

  // Greedy shortcut: from each kept state, the farthest later one reachable
  // by a valid motion (the space's own: a straight line, or the shortest
  // Dubins / Reeds-Shepp curve, never longer than what it replaces).
  auto* solution = pdef->getSolutionPath()->as<og::PathGeometric>();
  const std::vector<ob::State*>& s = solution->getStates();
  og::PathGeometric path(si);
  path.append(s.front());
  for (size_t i = 0; i + 1 < s.size();) {
    size_t j = s.size() - 1;
    while (j > i + 1 && !si->checkMotion(s[i], s[j])) --j;
    path.append(s[j]);
    i = j;
  }
  if (waypoints != nullptr)
    for (const ob::State* state : path.getStates()) waypoints->push_back(ToPose(state, planar, z));
  const double length = path.length();
  path.interpolate(static_cast<unsigned>(std::ceil(length / std::max(r.resolution, 1e-3))) + 1);
  for (const ob::State* state : path.getStates()) out.states.push_back(ToPose(state, planar, z));
  if (dense != nullptr) *dense = out.states;
  return out;
}

bool InBounds(const PlanRequest& r, const Pose& X) {
  const bool xy = X.p.x >= r.lo.x && X.p.x <= r.hi.x && X.p.y >= r.lo.y && X.p.y <= r.hi.y;
  return IsPlanar(r.space) ? xy : xy && X.p.z >= r.lo.z && X.p.z <= r.hi.z;
}

PlanResult PlanWithOmpl(const PlanRequest& request, const ValidityFn& valid) {
  PlanResult result;
  result.status = PlanStatus::kFailed;
  const auto fail = [&](const char* reason) {
    result.reason = reason;
    return result;
  };
  Pose goal = request.goal;
  if (IsPlanar(request.space)) goal.p.z = request.start.p.z;
  if (!InBounds(request, request.start)) return fail("invalid start: outside bounds");
  if (!InBounds(request, goal)) return fail("invalid goal: outside bounds");
  if (!valid(request.start)) return fail("invalid start: in collision");
  if (!valid(goal)) return fail("invalid goal: in collision");
  const int64_t budget = std::max<int64_t>(
      1, static_cast<int64_t>(std::llround(request.time_limit * kIterationsPerSecond)));
  PlanRequest r = request;
  r.goal = goal;
  Search search = RunSearch(r, r.space, valid, budget, &result.waypoints, &result.dense);
  result.iterations = search.iterations;
  if (!search.states.empty()) {
    result.status = PlanStatus::kSolved;
    result.reason = "solved";
    return result;
  }
  // Why not: a car-like failure is judged by the holonomic search (a
  // relaxation: where a free-turning robot cannot pass, a car cannot).
  if (!(r.space == Space::kSe2 || r.space == Space::kSe3)) {
    const Search relaxed = RunSearch(r, Space::kSe2, valid, budget, nullptr, nullptr);
    if (!relaxed.states.empty()) return fail("timeout");
    search = relaxed;
  }
  // A tree that stayed in a pocket while the other spread across the map:
  // that end is walled in.
  if (search.goal_reach * 3 < search.start_reach) return fail("goal enclosed/unreachable");
  if (search.start_reach * 3 < search.goal_reach) return fail("start enclosed/unreachable");
  return fail("timeout");
}

}  // namespace
}  // namespace swarmsim::planning

// The module's table (ompl_module.h); OMPL's console is silenced when the
// module is first asked for it, before any plan.
extern "C" __attribute__((visibility("default"))) const void* swarmsim_ompl_module() {
  static const swarmsim::planning::OmplModule module = [] {
    ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
    return swarmsim::planning::OmplModule{swarmsim::planning::kOmplModuleVersion,
                                          swarmsim::planning::PlanWithOmpl};
  }();
  return &module;
}
