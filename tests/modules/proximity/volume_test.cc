// Proximity sensor detection volumes (modules/proximity/volume.h): the
// reading is the nearest point of the part of each shape inside the volume,
// checked against hand-computed cases.
#include "modules/proximity/volume.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "framework/mesh.h"
#include "framework/scene.h"
#include "modules/proximity/proximity.h"

namespace swarmsim::proximity {
namespace {

constexpr double kTol = 1e-9;
constexpr double kDeg = M_PI / 180;

ShapeData Box(double x, double y, double z) {
  ShapeData s;
  s.kind = ShapeKind::kBox;
  s.size = {x, y, z};
  return s;
}
ShapeData Sphere(double radius) {
  ShapeData s;
  s.kind = ShapeKind::kSphere;
  s.size = {radius, 0, 0};
  return s;
}

// A closed cube mesh of half edge h, centred on its frame, wound
// counter-clockwise seen from outside.
ShapeData CubeMesh(double h) {
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i) v.push_back({i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h});
  const std::vector<MeshTriangle> t = {{{0, 2, 1}}, {{1, 2, 3}}, {{4, 5, 6}}, {{5, 7, 6}},
                                       {{0, 1, 4}}, {{1, 5, 4}}, {{2, 6, 3}}, {{3, 6, 7}},
                                       {{0, 4, 2}}, {{2, 4, 6}}, {{1, 3, 5}}, {{3, 7, 5}}};
  ShapeData s;
  s.kind = ShapeKind::kMesh;
  s.mesh = std::make_shared<TriangleMesh>("cube", v, t);
  s.size = {2 * h, 2 * h, 2 * h};
  return s;
}

ProximitySensorData Sensor(ProximityVolume volume, double range) {
  ProximitySensorData d;
  d.settings.Edit().volume = volume;
  d.settings.Edit().range = range;
  return d;
}

// A sensor of no robot at the world origin looking along +z, and the shapes
// around it (static: they belong to no robot and are not dynamic).
class VolumeTest : public ::testing::Test {
 protected:
  ObjectId AddSensor(const ProximitySensorData& sensor, const Pose& X_WS = {}) {
    return proximity::AddSensor(scene_.get(), "s", {}, X_WS, sensor);
  }
  ObjectId AddShape(const ShapeData& shape, const Pose& X_WS) {
    return scene_->AddShape("shape", {}, X_WS, shape);
  }
  const ProximitySensorData& Sense(ObjectId sensor) {
    scene_->UpdateWorldPoses();
    backend_ = MakeBackend();
    backend_->SetDetectableFilter(filter_);
    backend_->Build(*scene_, ProximitySettings{});
    backend_->Update(*scene_);
    backend_->SenseSceneSensors(scene_.get());
    return proximity::Sensor(*scene_, sensor);
  }
  static void ExpectPoint(const Vec3& got, const Vec3& want, double tol = kTol) {
    EXPECT_NEAR(got.x, want.x, tol);
    EXPECT_NEAR(got.y, want.y, tol);
    EXPECT_NEAR(got.z, want.z, tol);
  }

  void Reset() {
    backend_.reset();
    scene_ = std::make_unique<Scene>();
  }

  std::unique_ptr<Scene> scene_ = std::make_unique<Scene>();
  std::unique_ptr<ProximityBackend> backend_;
  DetectableFilter filter_;
};

// A wall (a big thin box) whose near face is the plane n . p = 0.5, n at 45
// deg from the axis: its nearest point (0.5 n) is outside a 30 deg cone, so
// the reading is on the cone's side, in the plane through the axis and n:
// along u = (sin 30, 0, cos 30), at 0.5 / (n . u) = 0.5 / cos 15.
TEST_F(VolumeTest, TiltedPlaneInsideACone) {
  ProximitySensorData cone = Sensor(ProximityVolume::kCone, 2);
  cone.settings.Edit().angle = 30 * kDeg;
  const ObjectId sensor = AddSensor(cone);
  const Vec3 n{std::sin(45 * kDeg), 0, std::cos(45 * kDeg)};
  const ObjectId wall =
      AddShape(Box(10, 10, 0.01), {n * 0.505, Quat::FromAxisAngle({0, 1, 0}, 45 * kDeg)});
  const ProximitySensorData& r = Sense(sensor);
  ASSERT_TRUE(r.detected);
  const double want = 0.5 / std::cos(15 * kDeg);
  EXPECT_NEAR(r.distance, want, kTol);
  ExpectPoint(r.p_SD(), Vec3{std::sin(30 * kDeg), 0, std::cos(30 * kDeg)} * want);
  ExpectPoint(r.normal, n * -1, 1e-12);
  EXPECT_EQ(r.detected_object, wall);
  // A narrower cone sees it farther: 0.5 / cos 35 at 10 deg.
  proximity::MutableSensors(scene_.get()).rows[0].settings.Edit().angle = 10 * kDeg;
  EXPECT_NEAR(Sense(sensor).distance, 0.5 / std::cos(35 * kDeg), kTol);
  // Facing it (n along the axis within the cone) the nearest point is its foot.
  proximity::MutableSensors(scene_.get()).rows[0].settings.Edit().angle = 50 * kDeg;
  EXPECT_NEAR(Sense(sensor).distance, 0.5, kTol);
  ExpectPoint(Sense(sensor).p_SD(), n * 0.5);
}

// A sphere (radius 0.2, centre 1 m away at 25 deg from the axis) across the
// +x side of a pyramid of half-angle 20 deg. The part inside is cut by the
// side plane x cos 20 = z sin 20, which passes sin 5 from the centre: the
// slice is a disc of radius sqrt(0.2^2 - sin^2 5) about the point cos 5 along
// the side; its nearest point lies on the side, inside the sphere.
TEST_F(VolumeTest, SphereAtThePyramidsEdgeReadsTheNearestPointOfItsInsidePart) {
  ProximitySensorData pyramid = Sensor(ProximityVolume::kPyramid, 2);
  pyramid.settings.Edit().angle = 20 * kDeg;
  pyramid.settings.Edit().angle_y = 20 * kDeg;
  const ObjectId sensor = AddSensor(pyramid);
  const Vec3 centre{std::sin(25 * kDeg), 0, std::cos(25 * kDeg)};
  const ObjectId ball = AddShape(Sphere(0.2), {centre, {}});
  const ProximitySensorData& r = Sense(sensor);
  ASSERT_TRUE(r.detected);
  const double s5 = std::sin(5 * kDeg);
  const double want = std::cos(5 * kDeg) - std::sqrt(0.04 - s5 * s5);
  EXPECT_NEAR(r.distance, want, kTol);
  const Vec3 side{std::sin(20 * kDeg), 0, std::cos(20 * kDeg)};
  ExpectPoint(r.p_SD(), side * want);
  EXPECT_EQ(r.detected_object, ball);
  // The normal: the sphere's, at its surface point nearest the detected one.
  ExpectPoint(r.normal, (side * want - centre).Normalized(), 1e-6);
  // Its own nearest point (0.8 m, at 25 deg) is outside: a ray would see nothing.
  EXPECT_GT(r.distance, 0.8 + 1e-3);
  // Wholly outside a 10 deg pyramid: nothing.
  proximity::MutableSensors(scene_.get()).rows[0].settings.Edit().angle = 10 * kDeg;
  EXPECT_FALSE(Sense(sensor).detected);
}

// The detectable-set hook (collections): a filtered-out shape is looked
// through, to the next one.
TEST_F(VolumeTest, DetectableFilterHidesShapes) {
  ProximitySensorData cone = Sensor(ProximityVolume::kCone, 2);
  const ObjectId sensor = AddSensor(cone);
  const ObjectId near = AddShape(Sphere(0.1), {{0, 0, 0.5}, {}});
  const ObjectId far = AddShape(Sphere(0.1), {{0, 0, 1}, {}});
  EXPECT_EQ(Sense(sensor).detected_object, near);
  filter_ = [&](ObjectId s, ObjectId shape) { return s == sensor && shape != near; };
  EXPECT_EQ(Sense(sensor).detected_object, far);
  EXPECT_NEAR(Sense(sensor).distance, 0.9, kTol);
}

// A sphere beyond both sides of a pyramid near its edge x = y = z tan 20:
// by symmetry the nearest inside point is on the edge, where the edge's
// ray e enters the sphere: t = e.c - sqrt((e.c)^2 - |c|^2 + r^2).
TEST_F(VolumeTest, SphereAcrossThePyramidsEdgeReadsOnTheEdge) {
  ProximitySensorData pyramid = Sensor(ProximityVolume::kPyramid, 2);
  pyramid.settings.Edit().angle = pyramid.settings.Edit().angle_y = 20 * kDeg;
  const ObjectId sensor = AddSensor(pyramid);
  const double t22 = std::tan(22 * kDeg), t20 = std::tan(20 * kDeg);
  const Vec3 c = Vec3{t22, t22, 1}.Normalized();
  AddShape(Sphere(0.1), {c, {}});
  const ProximitySensorData& r = Sense(sensor);
  ASSERT_TRUE(r.detected);
  const Vec3 e = Vec3{t20, t20, 1}.Normalized();
  const double ec = e.Dot(c);
  const double want = ec - std::sqrt(ec * ec - c.SquaredNorm() + 0.01);
  EXPECT_NEAR(r.distance, want, kTol);
  ExpectPoint(r.p_SD(), e * want);
}

// A cube mesh turned so that a corner points at the sensor: the reading is
// the corner, at 1 - h sqrt 3. Without front faces the sensor sees only the
// back faces, whose nearest points (the far side, behind the corner's
// faces) are farther.
TEST_F(VolumeTest, MeshCorner) {
  ProximitySensorData cone = Sensor(ProximityVolume::kCone, 2);
  cone.settings.Edit().angle = 20 * kDeg;
  const ObjectId sensor = AddSensor(cone);
  // Turn (-1, -1, -1)/sqrt 3 onto -z.
  const Vec3 from = Vec3{-1, -1, -1}.Normalized(), to{0, 0, -1};
  const Vec3 axis = from.Cross(to);
  const Quat q = Quat::FromAxisAngle(axis, std::acos(from.Dot(to)));
  const ObjectId cube = AddShape(CubeMesh(0.1), {{0, 0, 1}, q});
  const ProximitySensorData& r = Sense(sensor);
  ASSERT_TRUE(r.detected);
  EXPECT_NEAR(r.distance, 1 - 0.1 * std::sqrt(3.0), kTol);
  ExpectPoint(r.p_SD(), {0, 0, 1 - 0.1 * std::sqrt(3.0)});
  EXPECT_EQ(r.detected_object, cube);
  EXPECT_LT(r.normal.z, 0);  // a face seen from the sensor
  proximity::MutableSensors(scene_.get()).rows[0].settings.Edit().detect_front = false;
  const ProximitySensorData& back = Sense(sensor);
  ASSERT_TRUE(back.detected);
  EXPECT_GT(back.distance, 1 - 0.1 * std::sqrt(3.0) + 0.01);
  EXPECT_GT(back.normal.z, 0);  // facing away
}

// The mesh (a surface) and a box (a solid) of the same cube read the same
// where the nearest inside point is on the surface: the cube cut by the
// cone's side.
TEST_F(VolumeTest, MeshAndBoxOfTheSameCubeAgreeWhenCut) {
  // A wide cone sees the cube's own nearest point, at some angle a0.
  ProximitySensorData cone = Sensor(ProximityVolume::kCone, 3);
  cone.settings.Edit().angle = 40 * kDeg;
  const ObjectId sensor = AddSensor(cone);
  const Pose X_WC{{0.3, 0.1, 1}, Quat::FromRollPitchYaw(0.05, 0.03, 0.02)};
  AddShape(Box(0.2, 0.2, 0.2), X_WC);
  const Vec3 nearest = Sense(sensor).point;
  const double a0 = std::atan2(std::hypot(nearest.x, nearest.y), nearest.z);
  // A cone 0.5 deg narrower cuts the cube: the reading is on its side, farther.
  cone.settings.Edit().angle = a0 - 0.5 * kDeg;
  proximity::MutableSensors(scene_.get()).rows[0].settings.Edit().angle = cone.settings->angle;
  const ProximitySensorData box = Sense(sensor);
  ASSERT_TRUE(box.detected);
  EXPECT_NEAR(std::atan2(std::hypot(box.point.x, box.point.y), box.point.z), cone.settings->angle,
              1e-9);
  EXPECT_GT(box.distance, nearest.Norm() + 1e-3);  // 0.92 -> 0.95
  Reset();
  AddSensor(cone);
  AddShape(CubeMesh(0.1), X_WC);
  const ProximitySensorData& mesh = Sense(scene_->IdAt(0));
  ASSERT_TRUE(mesh.detected);
  EXPECT_NEAR(mesh.distance, box.distance, kTol);
  ExpectPoint(mesh.p_SD(), box.p_SD());
}

// A slab from z = 0.3 to 0.5 on the axis: 0.3 away; with a blind zone of
// 0.35 the nearest point left is inside the slab at 0.35; with a blind zone
// beyond the slab, nothing.
TEST_F(VolumeTest, BlindZone) {
  ProximitySensorData cone = Sensor(ProximityVolume::kCone, 1);
  const ObjectId sensor = AddSensor(cone);
  AddShape(Box(1, 1, 0.2), {{0, 0, 0.4}, {}});
  EXPECT_NEAR(Sense(sensor).distance, 0.3, kTol);
  proximity::MutableSensors(scene_.get()).rows[0].settings.Edit().blind_zone = 0.35;
  const ProximitySensorData& r = Sense(sensor);
  ASSERT_TRUE(r.detected);
  EXPECT_NEAR(r.distance, 0.35, kTol);
  ExpectPoint(r.p_SD(), {0, 0, 0.35});
  proximity::MutableSensors(scene_.get()).rows[0].settings.Edit().blind_zone = 0.6;
  EXPECT_FALSE(Sense(sensor).detected);
}

// A wall on the axis, turned 60 deg: its normal is 60 deg from the way back
// along the ray (55 deg at the nearest point of a 5 deg cone, on its side).
// A cut-off of 45 deg hides it, one of 70 deg does not; the same for a ray
// and a cone.
TEST_F(VolumeTest, DetectionAngleCutOff) {
  for (ProximityVolume volume : {ProximityVolume::kRay, ProximityVolume::kCone}) {
    SCOPED_TRACE(ToString(volume));
    Reset();
    ProximitySensorData s = Sensor(volume, 2);
    s.settings.Edit().angle = 5 * kDeg;
    const ObjectId sensor = AddSensor(s);
    AddShape(Box(4, 4, 0.01), {{0, 0, 1.005}, Quat::FromAxisAngle({0, 1, 0}, 60 * kDeg)});
    const ProximitySensorData& seen = Sense(sensor);
    ASSERT_TRUE(seen.detected);
    EXPECT_NEAR(-seen.normal.z, 0.5, 1e-9);  // cos 60
    proximity::MutableSensors(scene_.get()).rows[0].settings.Edit().max_detection_angle = 45 * kDeg;
    EXPECT_FALSE(Sense(sensor).detected);
    proximity::MutableSensors(scene_.get()).rows[0].settings.Edit().max_detection_angle = 70 * kDeg;
    EXPECT_TRUE(Sense(sensor).detected);
  }
}

// Cylinder and disc volumes: a sphere beside the axis is inside a cylinder
// of radius 0.3 but not 0.1; a box at 60 deg in the xy plane is inside a
// disc of half sector 70 deg but not 50 deg.
TEST_F(VolumeTest, CylinderAndDisc) {
  ProximitySensorData cylinder = Sensor(ProximityVolume::kCylinder, 2);
  cylinder.settings.Edit().radius = 0.3;
  const ObjectId c = AddSensor(cylinder);
  AddShape(Sphere(0.05), {{0.2, 0, 1}, {}});
  const ProximitySensorData r = Sense(c);
  ASSERT_TRUE(r.detected);
  const double d = std::hypot(0.2, 1.0);
  EXPECT_NEAR(r.distance, d - 0.05, kTol);
  ExpectPoint(r.p_SD(), Vec3{0.2, 0, 1} * (1 - 0.05 / d));
  // Cut by the side x = 0.17 of a cylinder of radius 0.17: the detected
  // point is on the side.
  proximity::MutableSensors(scene_.get()).rows[0].settings.Edit().radius = 0.17;
  const ProximitySensorData& cut = Sense(c);
  ASSERT_TRUE(cut.detected);
  EXPECT_NEAR(std::hypot(cut.point.x, cut.point.y), 0.17, 1e-9);
  EXPECT_GT(cut.distance, r.distance);
  // Wholly outside a cylinder of radius 0.1.
  proximity::MutableSensors(scene_.get()).rows[0].settings.Edit().radius = 0.1;
  EXPECT_FALSE(Sense(c).detected);

  Reset();
  ProximitySensorData disc = Sensor(ProximityVolume::kDisc, 2);
  disc.settings.Edit().angle = 70 * kDeg;
  const ObjectId s = AddSensor(disc);
  AddShape(Box(0.1, 0.1, 0.1), {{std::cos(60 * kDeg), std::sin(60 * kDeg), 0}, {}});
  EXPECT_TRUE(Sense(s).detected);
  proximity::MutableSensors(scene_.get()).rows[0].settings.Edit().angle = 50 * kDeg;
  EXPECT_FALSE(Sense(s).detected);
}

// Many static shapes, sensors of each volume at random poses: the backend's
// broad phase (the octree's buckets, the volume's box) finds the same
// nearest shape as testing every shape.
TEST_F(VolumeTest, BroadPhaseMissesNothing) {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<ObjectId> shapes;
  for (int i = 0; i < 300; ++i) {
    const Pose X_WS{{2 * u(random), 2 * u(random), 0.5 * u(random)},
                    Quat::FromRollPitchYaw(u(random), u(random), u(random))};
    shapes.push_back(AddShape(
        i % 2 ? Sphere(0.03 + 0.02 * u(random)) : Box(0.1 + 0.05 * u(random), 0.05, 0.08), X_WS));
  }
  const ProximityVolume kinds[] = {ProximityVolume::kCone, ProximityVolume::kPyramid,
                                   ProximityVolume::kCylinder, ProximityVolume::kDisc};
  std::vector<ObjectId> sensors;
  for (int i = 0; i < 40; ++i) {
    ProximitySensorData s = Sensor(kinds[i % 4], 1.5);
    s.settings.Edit().angle = 25 * kDeg;
    s.settings.Edit().angle_y = 15 * kDeg;
    s.settings.Edit().radius = 0.15;
    s.settings.Edit().thickness = 0.2;
    sensors.push_back(
        AddSensor(s, {{2 * u(random), 2 * u(random), 0.5 * u(random)},
                      Quat::FromRollPitchYaw(3 * u(random), 3 * u(random), 3 * u(random))}));
  }
  Sense(sensors[0]);
  int detected = 0;
  for (const ObjectId sensor : sensors) {
    const ProximitySensorData& r = proximity::Sensor(*scene_, sensor);
    const Volume volume = MakeVolume(r);
    const Pose X_SW = scene_->world_pose(sensor).Inverse();
    VolumeHit best{INFINITY, {}, {}};
    ObjectId nearest;
    for (const ObjectId shape : shapes) {
      const PlacedShape placed =
          PlaceShape(scene_->shape(shape), scene_->world_pose(shape), shape, -1);
      VolumeHit h;
      if (NearestInVolume(volume, placed, X_SW, best.distance, &h)) best = h, nearest = shape;
    }
    ASSERT_EQ(r.detected, best.distance <= r.range());
    if (!r.detected) continue;
    ++detected;
    EXPECT_EQ(r.distance, best.distance);
    EXPECT_EQ(r.detected_object, nearest);
  }
  EXPECT_GT(detected, 10);
}

// Random boxes, spheres, cylinders and capsules against each volume (with a blind zone): the
// reading is a point of the box inside the volume, and no point of a dense sample of the shape
// inside the volume is nearer (a shape the sample finds inside is found).
TEST(VolumePropertyTest, ReadingIsInsideAndNoSampledPointIsNearer) {
  std::mt19937_64 random(5);
  std::uniform_real_distribution<double> u(-1, 1);
  int detected = 0;
  for (ProximityVolume kind : {ProximityVolume::kCone, ProximityVolume::kPyramid,
                               ProximityVolume::kCylinder, ProximityVolume::kDisc}) {
    for (int trial = 0; trial < 40; ++trial) {
      SCOPED_TRACE(std::string(ToString(kind)) + " trial " + std::to_string(trial));
      ProximitySensorData sensor;
      sensor.settings.Edit().volume = kind;
      sensor.settings.Edit().range = 3;
      sensor.settings.Edit().angle = (20 + 10 * u(random)) * kDeg;
      sensor.settings.Edit().angle_y = (15 + 5 * u(random)) * kDeg;
      sensor.settings.Edit().radius = 0.2;
      sensor.settings.Edit().thickness = 0.1;
      sensor.settings.Edit().blind_zone = 0.2;
      const Volume volume = MakeVolume(sensor);
      // A shape around 1 m ahead along the volume's axis, off it by up to 0.5 m.
      const Vec3 half{0.1 + 0.1 * std::abs(u(random)), 0.1 + 0.1 * std::abs(u(random)),
                      0.1 + 0.1 * std::abs(u(random))};
      Vec3 centre{0.5 * u(random), 0.5 * u(random), 1 + 0.3 * u(random)};
      if (kind == ProximityVolume::kDisc) centre = {centre.z, centre.x, 0.1 * u(random)};
      const Pose X_WB{centre, Quat::FromRollPitchYaw(u(random), u(random), u(random))};
      // Box, sphere, cylinder or capsule in turn, and whether a point (shape
      // frame) is in it.
      ShapeData data = Box(2 * half.x, 2 * half.y, 2 * half.z);
      const double r = half.x;
      if (trial % 4 == 1) data = Sphere(r);
      if (trial % 4 >= 2) {
        data.kind = trial % 4 == 2 ? ShapeKind::kCylinder : ShapeKind::kCapsule;
        data.size = {r, 0, 2 * (half.z + r)};
      }
      const Vec3 bound = data.kind == ShapeKind::kBox      ? half
                         : data.kind == ShapeKind::kSphere ? Vec3{r, r, r}
                                                           : Vec3{r, r, half.z + r};
      auto inside = [&](const Vec3& p, double tol) {
        switch (data.kind) {
          case ShapeKind::kSphere: return p.Norm() <= r + tol;
          case ShapeKind::kCylinder:
            return std::hypot(p.x, p.y) <= r + tol && std::abs(p.z) <= bound.z + tol;
          case ShapeKind::kCapsule:
            return (p - Vec3{0, 0, std::clamp(p.z, -half.z, half.z)}).Norm() <= r + tol;
          default:
            return std::abs(p.x) <= half.x + tol && std::abs(p.y) <= half.y + tol &&
                   std::abs(p.z) <= half.z + tol;
        }
      };
      const PlacedShape shape = PlaceShape(data, X_WB, ObjectId{}, -1);
      VolumeHit hit;
      const bool found = NearestInVolume(volume, shape, Pose{}, INFINITY, &hit);
      double sampled = INFINITY;
      std::uniform_real_distribution<double> unit(-1, 1);
      for (int k = 0; k < 20000; ++k) {
        const Vec3 p_B{bound.x * unit(random), bound.y * unit(random), bound.z * unit(random)};
        const Vec3 p = X_WB * p_B;
        if (inside(p_B, 0) && InVolume(volume, p, 0)) sampled = std::min(sampled, p.Norm());
      }
      if (!found) {
        EXPECT_EQ(sampled, INFINITY);
        continue;
      }
      ++detected;
      EXPECT_TRUE(InVolume(volume, hit.point, 1e-8));
      EXPECT_TRUE(inside(X_WB.Inverse() * hit.point, 1e-8));
      EXPECT_NEAR(hit.distance, hit.point.Norm(), 1e-12);
      EXPECT_LE(hit.distance, sampled + 1e-9);
    }
  }
  EXPECT_GT(detected, 80);  // most trials see the shape
}

TEST(RandomRaysTest, DirectionsStayInTheConeAndDependOnTheStream) {
  std::vector<Vec3> a(64), b(64), c(64);
  RandomRayDirections(7, 1, 20 * kDeg, 64, a.data());
  RandomRayDirections(7, 1, 20 * kDeg, 64, b.data());
  RandomRayDirections(7, 2, 20 * kDeg, 64, c.data());
  for (int i = 0; i < 64; ++i) {
    EXPECT_EQ(a[i], b[i]);
    EXPECT_NEAR(a[i].Norm(), 1, 1e-12);
    EXPECT_GE(a[i].z, std::cos(20 * kDeg) - 1e-12);
  }
  EXPECT_NE(a[0], c[0]);
}

}  // namespace
}  // namespace swarmsim::proximity
