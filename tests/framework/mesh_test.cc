// The triangle mesh asset: bounds, closedness, exact ray casts through its
// BVH, the inside rule of closed meshes, and the mistakes it refuses.
#include "framework/mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "framework/error.h"

namespace swarmsim {
namespace {

// A box of full extents `size` centred on `c`, faces wound outwards.
// `drop_face`: leave out face k (0..5) to make an open mesh.
TriangleMesh BoxMesh(const Vec3& size, const Vec3& c = {}, int drop_face = -1) {
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i)
    v.push_back(c + Vec3{(i & 1 ? 0.5 : -0.5) * size.x, (i & 2 ? 0.5 : -0.5) * size.y,
                         (i & 4 ? 0.5 : -0.5) * size.z});
  const uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  std::vector<MeshTriangle> t;
  for (int f = 0; f < 6; ++f) {
    if (f == drop_face) continue;
    const uint32_t* q = quads[f];
    t.push_back({{q[0], q[1], q[2]}});
    t.push_back({{q[0], q[2], q[3]}});
  }
  return TriangleMesh("box", v, t);
}

// The slab answer for an axis-aligned box: nearest t in [0, max_t] or -1.
double SlabHit(const Vec3& o, const Vec3& d, const Vec3& lo, const Vec3& hi, double max_t) {
  double a = 0, b = max_t;
  const double oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
  const double l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
  for (int i = 0; i < 3; ++i) {
    if (dd[i] == 0) {
      if (oo[i] < l[i] || oo[i] > h[i]) return -1;
      continue;
    }
    double t1 = (l[i] - oo[i]) / dd[i], t2 = (h[i] - oo[i]) / dd[i];
    if (t1 > t2) std::swap(t1, t2);
    a = std::max(a, t1);
    b = std::min(b, t2);
    if (a > b) return -1;
  }
  return a;
}

TEST(TriangleMesh, BoundsRadiiAndClosedness) {
  const TriangleMesh box = BoxMesh({0.2, 0.4, 0.6}, {0.1, 0, 0});
  EXPECT_EQ(box.vertices().size(), 8u);
  EXPECT_EQ(box.triangles().size(), 12u);
  EXPECT_TRUE(box.closed());
  EXPECT_EQ(box.lo(), (Vec3{0, -0.2, -0.3}));
  EXPECT_EQ(box.hi(), (Vec3{0.2, 0.2, 0.3}));
  EXPECT_NEAR(box.footprint_radius(), std::hypot(0.2, 0.2), 1e-15);
  EXPECT_NEAR(box.CenteredExtents().x, 0.4, 1e-15);  // holds the off-centre box
  EXPECT_FALSE(BoxMesh({1, 1, 1}, {}, 2).closed());
}

TEST(TriangleMesh, RayCastsMatchTheBoxExactly) {
  const Vec3 size{0.3, 0.5, 0.7}, c{0.05, -0.1, 0.2};
  const TriangleMesh box = BoxMesh(size, c);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 o{u(rng), u(rng), u(rng)};
    const Vec3 d = Vec3{u(rng), u(rng), u(rng)}.Normalized();
    const double expected = SlabHit(o, d, c - size * 0.5, c + size * 0.5, 1.5);
    double t = -1;
    const bool hit = box.RayCast(o, d, 1.5, &t);
    ASSERT_EQ(hit, expected >= 0) << i;
    if (hit) {
      EXPECT_NEAR(t, expected, 1e-12) << i;
    }
    hits += hit;
  }
  EXPECT_GT(hits, 100);
}

TEST(TriangleMesh, ClosedMeshIsSolidOpenMeshIsASurface) {
  double t = -1;
  // Inside a closed box: hit at 0, whatever the range.
  EXPECT_TRUE(BoxMesh({1, 1, 1}).RayCast({0, 0, 0}, {1, 0, 0}, 0.1, &t));
  EXPECT_EQ(t, 0);
  // Without its -x face, the box is a surface: from inside, the +x face at 0.5.
  const TriangleMesh open = BoxMesh({1, 1, 1}, {}, 0);
  EXPECT_TRUE(open.RayCast({0, 0, 0}, {1, 0, 0}, 1, &t));
  EXPECT_NEAR(t, 0.5, 1e-15);
  EXPECT_FALSE(open.RayCast({0, 0, 0}, {-1, 0, 0}, 1, &t));  // through the missing face
}

TEST(TriangleMesh, AnyTriangleWithin) {
  const TriangleMesh box = BoxMesh({1, 1, 1});
  EXPECT_TRUE(box.AnyTriangleWithin({0.7, 0, 0}, 0.21));
  EXPECT_FALSE(box.AnyTriangleWithin({0.7, 0, 0}, 0.19));
  EXPECT_FALSE(box.AnyTriangleWithin({0, 0, 0}, 0.49));  // the centre: faces 0.5 away
}

TEST(TriangleMesh, RefusesEmptyOrBrokenInput) {
  EXPECT_THROW(TriangleMesh("m", {{0, 0, 0}}, {}), Error);
  EXPECT_THROW(TriangleMesh("m", {{0, 0, 0}, {1, 0, 0}}, {{{0, 1, 2}}}), Error);
  EXPECT_THROW(TriangleMesh("m", {{0, 0, 0}, {1, 0, 0}, {NAN, 0, 0}}, {{{0, 1, 2}}}), Error);
  // Only degenerate triangles: nothing left.
  EXPECT_THROW(TriangleMesh("m", {{0, 0, 0}, {1, 0, 0}}, {{{0, 1, 1}}}), Error);
}

// Triangles without area (repeated or collinear corners, as an STL file can
// write them: each facet has its own vertices) are dropped; ODE's mesh
// collider crashed on one. A tiny but real triangle stays.
TEST(TriangleMesh, DropsTrianglesWithoutArea) {
  const TriangleMesh m("m",
                       {{0, 0, 0},
                        {0.1, 0, 0},
                        {0, 0.1, 0},
                        {1, 1, 1},
                        {1, 1, 1},
                        {1, 1, 1},
                        {0, 0, 0},
                        {1, 0, 0},
                        {2, 0, 0},
                        {5, 5, 5},
                        {5 + 1e-6, 5, 5},
                        {5, 5 + 1e-6, 5}},
                       {{{0, 1, 2}}, {{3, 4, 5}}, {{6, 7, 8}}, {{9, 10, 11}}});
  EXPECT_EQ(m.triangles().size(), 2u);
  EXPECT_THROW(TriangleMesh("m", {{1, 1, 1}, {1, 1, 1}, {1, 1, 1}}, {{{0, 1, 2}}}), Error);
}

}  // namespace
}  // namespace swarmsim
