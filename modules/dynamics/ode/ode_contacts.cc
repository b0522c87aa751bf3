// Contacts in ODE: the broadphase's candidate pairs in a fixed order, their
// contact points on every thread, and the contact joints (friction,
// restitution, moving surfaces). See "Threads and determinism" in
// ode_backend.h.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "framework/scheduler.h"
#include "modules/dynamics/ode/ode_internal.h"
#include "modules/dynamics/ode/ode_world.h"

namespace swarmsim::ode {

namespace {

// Restitution applies above this approach speed, m/s (as in the Box2D backend).
constexpr double kBounceVelocity = 0.1;

}  // namespace

void OdeWorld::FindCandidatePairs() {
  // Broadphase on this thread. The spaces list their geoms in the order the
  // solver last moved them, which depends on the order its threads finished
  // the islands: the pairs go in the geoms' build order (Collide: each with
  // its first-built geom first).
  pairs_.clear();
  dSpaceCollide(space_, this, &OdeWorld::NearCallback);
  std::sort(pairs_.begin(), pairs_.end(),
            [](const CandidatePair& x, const CandidatePair& y) { return x.order < y.order; });
}

Vec3 OdeWorld::SurfaceVelocity(dGeomID geom, const GeomInfo& info, const Vec3& p_W) const {
  if (info.surface < 0) return {};
  const MovingSurface& surface = surfaces_[info.surface];
  dQuaternion q;
  dGeomGetQuaternion(geom, q);
  const Quat q_WS{q[0], q[1], q[2], q[3]};
  const Vec3 p_S = q_WS.Conjugate().Rotate(p_W - ToVec3(dGeomGetPosition(geom)));
  return q_WS.Rotate(surface.v_S + surface.w_S.Cross(p_S));
}

void OdeWorld::NearCallback(void* data, dGeomID a, dGeomID b) {
  OdeWorld* self = static_cast<OdeWorld*>(data);
  // A robot's sub-space against a geom or another robot's: their geoms
  // pairwise (never a robot's geoms with each other).
  if (dGeomIsSpace(a) || dGeomIsSpace(b)) {
    dSpaceCollide2(a, b, data, &OdeWorld::NearCallback);
    return;
  }
  self->Collide(a, b);
}

void OdeWorld::Collide(dGeomID a, dGeomID b) {
  dBodyID ba = dGeomGetBody(a), bb = dGeomGetBody(b);
  const bool dynamic_a = ba && !dBodyIsKinematic(ba);
  const bool dynamic_b = bb && !dBodyIsKinematic(bb);
  if (!dynamic_a && !dynamic_b) return;
  if (ba == bb) return;
  const GeomInfo& ia = geom_info_[reinterpret_cast<uintptr_t>(dGeomGetData(a)) - 1];
  const GeomInfo& ib = geom_info_[reinterpret_cast<uintptr_t>(dGeomGetData(b)) - 1];
  if (ia.instance >= 0 && ia.instance == ib.instance) return;
  if (ba && bb && dAreConnectedExcluding(ba, bb, dJointTypeContact)) return;
  if (has_mounts_ && HeldApart(a, ba, b, bb)) return;
  // Geom data: build index + 1.
  uint64_t first = reinterpret_cast<uintptr_t>(dGeomGetData(a));
  uint64_t second = reinterpret_cast<uintptr_t>(dGeomGetData(b));
  if (first > second) {
    std::swap(a, b);
    std::swap(first, second);
  }
  pairs_.push_back({a, b, 0, first << 32 | second});
}

namespace {

// A trimesh pair's contact points, up to kMeshProbe, reduced to `m` spread
// over the contact patch: ODE's trimesh colliders stop at the first m they
// meet (a plane's: the first m vertices below it, in the file's order), which
// may all lie on one side of a base, so that a robot standing still on its
// mesh tipped over or turned. The deepest first, then each time the point
// farthest from those kept (ties: the earlier one), in ODE's order.
constexpr int kMeshProbe = 64;
// A mesh pair keeps up to this many (a box on a plane has its 4 corners; a
// rounded mesh base needs more of its rim to stand as it would).
constexpr int kMeshContacts = 12;

int SpreadContacts(dGeomID a, dGeomID b, int m, dContactGeom* out) {
  dContactGeom probe[kMeshProbe];
  const int n = dCollide(a, b, kMeshProbe, probe, sizeof(dContactGeom));
  if (n <= m) {
    std::copy_n(probe, n, out);
    return n;
  }
  int deepest = 0;
  for (int i = 1; i < n; ++i)
    if (probe[i].depth > probe[deepest].depth) deepest = i;
  bool taken[kMeshProbe] = {};
  double nearest[kMeshProbe];  // squared distance to the nearest point kept
  const auto add = [&](int i, int k) {
    out[k] = probe[i];
    taken[i] = true;
    for (int j = 0; j < n; ++j) {
      const double dx = probe[j].pos[0] - probe[i].pos[0], dy = probe[j].pos[1] - probe[i].pos[1],
                   dz = probe[j].pos[2] - probe[i].pos[2];
      const double d = dx * dx + dy * dy + dz * dz;
      nearest[j] = k == 0 ? d : std::min(nearest[j], d);
    }
  };
  add(deepest, 0);
  for (int k = 1; k < m; ++k) {
    int far = -1;
    for (int j = 0; j < n; ++j)
      if (!taken[j] && (far < 0 || nearest[j] > nearest[far])) far = j;
    add(far, k);
  }
  return m;
}

bool IsMesh(dGeomID g) { return dGeomGetClass(g) == dTriMeshClass; }

}  // namespace

int OdeWorld::ContactCapacity() const {
  return has_meshes_ ? std::max(options_.max_contacts, kMeshContacts) : options_.max_contacts;
}

void OdeWorld::FindContacts() {
  const size_t m = static_cast<size_t>(ContactCapacity());
  if (pair_contacts_.size() < pairs_.size() * m) pair_contacts_.resize(pairs_.size() * m);
  auto narrow = [this, m](int64_t begin, int64_t end) {
    dAllocateODEDataForThread(dAllocateMaskAll);
    for (int64_t k = begin; k < end; ++k) {
      CandidatePair& pair = pairs_[static_cast<size_t>(k)];
      dContactGeom* out = &pair_contacts_[static_cast<size_t>(k) * m];
      pair.count =
          has_meshes_ && (IsMesh(pair.a) || IsMesh(pair.b))
              ? SpreadContacts(pair.a, pair.b, std::min(static_cast<int>(m), kMeshProbe), out)
              : dCollide(pair.a, pair.b, options_.max_contacts, out, sizeof(dContactGeom));
    }
  };
  // Debian's trimesh collider (OPCODE) is not thread-safe: worlds with
  // meshes find their contacts on this thread.
  constexpr int64_t kGrain = 256;
  const int64_t n = static_cast<int64_t>(pairs_.size());
  if (settings_.scheduler && !has_meshes_)
    settings_.scheduler->ParallelFor(0, n, kGrain, narrow);
  else
    narrow(0, n);
}

void OdeWorld::AddContacts(size_t k) {
  const CandidatePair& pair = pairs_[k];
  const dGeomID a = pair.a, b = pair.b;
  dBodyID ba = dGeomGetBody(a), bb = dGeomGetBody(b);
  const GeomInfo& ia = geom_info_[reinterpret_cast<uintptr_t>(dGeomGetData(a)) - 1];
  const GeomInfo& ib = geom_info_[reinterpret_cast<uintptr_t>(dGeomGetData(b)) - 1];
  const double mu = std::sqrt(ia.friction * ib.friction);
  const double bounce = std::max(ia.restitution, ib.restitution);
  // Moving surfaces (conveyor belts): friction drives the contact towards
  // a's surface point moving as b's, v_a + u_a = v_b + u_b (u: each
  // surface's velocity at the contact point), so the bodies' relative
  // velocity v_a - v_b is u = u_b - u_a in the contact plane. ODE
  // constrains (v_1 - v_2) . fdir1 = motion1 where body 1 is a's body, or
  // b's when a has none (a static belt: ODE then swaps the two).
  const bool moving = ia.surface >= 0 || ib.surface >= 0;
  const size_t first = k * static_cast<size_t>(ContactCapacity());
  for (int i = 0; i < pair.count; ++i) {
    dContact c{};
    c.geom = pair_contacts_[first + static_cast<size_t>(i)];
    c.surface.mode = dContactApprox1 | (bounce > 0 ? dContactBounce : 0);
    c.surface.mu = mu;
    c.surface.bounce = bounce;
    c.surface.bounce_vel = kBounceVelocity;
    if (moving) {
      const Vec3 p_W = ToVec3(c.geom.pos);
      const Vec3 u = SurfaceVelocity(b, ib, p_W) - SurfaceVelocity(a, ia, p_W);
      const Vec3 normal = ToVec3(c.geom.normal);
      const Vec3 t = u - normal * normal.Dot(u);
      const double speed = t.Norm();
      if (speed > 1e-9) {
        const Vec3 direction = t / speed;
        c.fdir1[0] = direction.x;
        c.fdir1[1] = direction.y;
        c.fdir1[2] = direction.z;
        c.surface.mode |= dContactFDir1 | dContactMotion1;
        c.surface.motion1 = ba ? speed : -speed;
      }
    }
    dJointID joint = dJointCreateContact(world_, contacts_, &c);
    dJointAttach(joint, ba, bb);
  }
}

}  // namespace swarmsim::ode
