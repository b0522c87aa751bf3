#include "swarm/python/sensor_arrays.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "framework/scene.h"
#include "modules/blobs/blob_camera.h"
#include "modules/collision/rows.h"
#include "modules/force_sensor/force_sensor.h"
#include "modules/rendering/vision_sensor.h"

namespace swarmsim::python {

namespace {

// An output array of T and `shape`: `out` if it is one, else a new one.
template <typename T>
py::array_t<T> OutArrayOf(const std::vector<py::ssize_t>& shape, const py::object& out) {
  if (out.is_none()) return py::array_t<T>(shape);
  CheckOut(out, py::dtype::of<T>(), shape);
  return py::reinterpret_borrow<py::array_t<T>>(out);
}

// The reading of each vision sensor, all of one resolution.
std::vector<rendering::VisionReading> VisionReadings(const Scene& scene,
                                                     const std::vector<uint32_t>& slots,
                                                     const std::vector<std::string>& who) {
  std::vector<rendering::VisionReading> out(slots.size());
  for (size_t i = 0; i < slots.size(); ++i) {
    if (!rendering::ReadVisionSensor(scene, slots[i], &out[i]))
      throw py::value_error(who[i] + " is not a vision sensor");
    if (out[i].width != out[0].width || out[i].height != out[0].height)
      throw py::value_error(who[i] + " sees " + std::to_string(out[i].width) + "x" +
                            std::to_string(out[i].height) + " pixels, " + who[0] + " " +
                            std::to_string(out[0].width) + "x" + std::to_string(out[0].height) +
                            ": one array needs one resolution");
  }
  return out;
}

template <typename Row>
const Rows<Row>* RowsNamed(const Scene& scene, const char* name) {
  ObjectType type;
  return scene.FindType(name, &type) ? &scene.rows<Row>(type) : nullptr;
}

// Rows of a type's live objects, in slot order.
template <typename Row>
std::vector<std::pair<uint32_t, const Row*>> LiveRows(const Scene& scene, const char* name) {
  std::vector<std::pair<uint32_t, const Row*>> out;
  if (const Rows<Row>* rows = RowsNamed<Row>(scene, name))
    for (size_t r = 0; r < rows->rows.size(); ++r)
      if (scene.alive_at(rows->owners[r])) out.emplace_back(rows->owners[r], &rows->rows[r]);
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  return out;
}

py::array_t<double> Points(const std::vector<Vec3>& points) {
  py::array_t<double> a({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
  double* d = a.mutable_data();
  for (const Vec3& p : points) *d++ = p.x, *d++ = p.y, *d++ = p.z;
  return a;
}

}  // namespace

DeviceTable Devices(const Scene& scene, const ModelLayout& layout, const char* type_name) {
  DeviceTable table;
  ObjectType type;
  if (!scene.FindType(type_name, &type)) return table;
  bool first = true;
  for (size_t i = 0; i < layout.robots.size(); ++i) {
    const ModelInstance& inst = scene.instance(layout.robots[i]);
    std::vector<std::string> names;
    std::vector<uint32_t> slots;
    for (const uint32_t slot : inst.objects)
      if (scene.type_at(slot) == type) {
        names.push_back(scene.name_at(slot));
        slots.push_back(slot);
      }
    IndexRepeats(&names);
    if (first) {
      table.names = names;
      first = false;
    } else if (names != table.names) {
      throw py::value_error("robot '" + inst.name + "' has other " + type_name +
                            " objects than robot '" + scene.instance(layout.robots[0]).name +
                            "': arrays need one layout (pass model=)");
    }
    table.slots.insert(table.slots.end(), slots.begin(), slots.end());
  }
  return table;
}

size_t DeviceColumn(const DeviceTable& table, const std::string& name, const char* what) {
  std::string known;
  for (const std::string& n : table.names) known += (known.empty() ? "" : ", ") + n;
  if (name.empty()) {
    if (table.names.size() == 1) return 0;
    throw py::value_error(std::string("the robots have ") +
                          (table.names.empty() ? std::string("no ") + what
                                               : std::to_string(table.names.size()) + " " + what +
                                                     "s (" + known + "): name one"));
  }
  for (size_t j = 0; j < table.names.size(); ++j)
    if (table.names[j] == name) return j;
  throw py::value_error("no " + std::string(what) + " '" + name + "' on the robots (" +
                        (known.empty() ? std::string("they have none") : known) + ")");
}

py::array VisionImages(const Scene& scene, const std::vector<uint32_t>& slots, bool filtered,
                       const py::object& out, const std::vector<std::string>& who) {
  const std::vector<rendering::VisionReading> readings = VisionReadings(scene, slots, who);
  const int w = readings.empty() ? 0 : readings[0].width;
  const int h = readings.empty() ? 0 : readings[0].height;
  auto a = OutArrayOf<uint8_t>({static_cast<py::ssize_t>(slots.size()), h, w, 3}, out);
  uint8_t* d = a.mutable_data();
  const size_t size = static_cast<size_t>(w) * static_cast<size_t>(h) * 3;
  for (size_t i = 0; i < readings.size(); ++i, d += size) {
    const Image* image =
        filtered && readings[i].filtered ? readings[i].filtered : readings[i].image;
    if (image != nullptr && image->rgb.size() == size)
      std::memcpy(d, image->rgb.data(), size);
    else
      std::memset(d, 0, size);
  }
  return a;
}

py::array VisionDepths(const Scene& scene, const std::vector<uint32_t>& slots,
                       const py::object& out, const std::vector<std::string>& who) {
  const std::vector<rendering::VisionReading> readings = VisionReadings(scene, slots, who);
  const int w = readings.empty() ? 0 : readings[0].width;
  const int h = readings.empty() ? 0 : readings[0].height;
  for (size_t i = 0; i < readings.size(); ++i)
    if (!readings[i].depth)
      throw py::value_error(who[i] + " keeps no depth image (its 'depth' setting is false)");
  auto a = OutArrayOf<float>({static_cast<py::ssize_t>(slots.size()), h, w}, out);
  float* d = a.mutable_data();
  const size_t size = static_cast<size_t>(w) * static_cast<size_t>(h);
  for (size_t i = 0; i < readings.size(); ++i, d += size) {
    const Image* image = readings[i].image;
    if (image != nullptr && image->depth.size() == size)
      std::memcpy(d, image->depth.data(), size * sizeof(float));
    else
      std::fill(d, d + size, 0.0f);
  }
  return a;
}

py::dict BlobCameras(const Scene& scene, const std::vector<uint32_t>& slots) {
  const Rows<BlobCameraRow>* rows = RowsNamed<BlobCameraRow>(scene, kBlobCameraTypeName);
  const size_t n = slots.size();
  size_t m = 0;
  for (const uint32_t slot : slots) m += rows->rows[scene.row_at(slot)].blobs.size();
  const auto sm = static_cast<py::ssize_t>(m);
  py::array_t<int64_t> offsets(static_cast<py::ssize_t>(n + 1)), robot(sm);
  py::array_t<double> color({sm, py::ssize_t{3}}), distance(sm), bearing(sm), elevation(sm);
  int64_t *o = offsets.mutable_data(), *who = robot.mutable_data();
  double *c = color.mutable_data(), *di = distance.mutable_data(), *be = bearing.mutable_data(),
         *el = elevation.mutable_data();
  size_t k = 0;
  for (size_t i = 0; i < n; ++i) {
    o[i] = static_cast<int64_t>(k);
    for (const Blob& b : rows->rows[scene.row_at(slots[i])].blobs) {
      c[3 * k] = b.color.x, c[3 * k + 1] = b.color.y, c[3 * k + 2] = b.color.z;
      di[k] = b.distance, be[k] = b.bearing, el[k] = b.elevation;
      who[k] = scene.IsValid(b.led) ? scene.instance_of(b.led) : -1;
      ++k;
    }
  }
  o[n] = static_cast<int64_t>(k);
  py::dict out;
  out["offsets"] = offsets;
  out["color"] = color;
  out["distance"] = distance;
  out["bearing"] = bearing;
  out["elevation"] = elevation;
  out["robot"] = robot;
  return out;
}

Array ForceSensors(const Scene& scene, const DeviceTable& table, size_t robots,
                   const py::object& out) {
  const auto s = static_cast<py::ssize_t>(table.names.size());
  Array a = OutArray({static_cast<py::ssize_t>(robots), s, 6}, out);
  double* d = a.mutable_data();
  const Rows<ForceSensorData>* rows = force_sensor::RowsOf(scene);
  for (size_t k = 0; k < table.slots.size(); ++k, d += 6) {
    const ForceSensorData& f = rows->rows[scene.row_at(table.slots[k])];
    if (!f.has_reading) {
      std::fill(d, d + 6, std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    d[0] = f.force.x, d[1] = f.force.y, d[2] = f.force.z;
    d[3] = f.torque.x, d[4] = f.torque.y, d[5] = f.torque.z;
  }
  return a;
}

py::array ForceSensorsBroken(const Scene& scene, const DeviceTable& table, size_t robots) {
  py::array_t<bool> a(
      {static_cast<py::ssize_t>(robots), static_cast<py::ssize_t>(table.names.size())});
  bool* d = a.mutable_data();
  const Rows<ForceSensorData>* rows = force_sensor::RowsOf(scene);
  for (size_t k = 0; k < table.slots.size(); ++k)
    d[k] = rows->rows[scene.row_at(table.slots[k])].broken;
  return a;
}

py::dict Distances(const Scene& scene) {
  const auto rows = LiveRows<collision::DistanceRow>(scene, "distance");
  const auto k = static_cast<py::ssize_t>(rows.size());
  py::list names;
  py::array_t<bool> found(k);
  py::array_t<double> distance(k), p1({k, py::ssize_t{3}}), p2({k, py::ssize_t{3}});
  for (size_t i = 0; i < rows.size(); ++i) {
    const collision::DistanceRow& r = *rows[i].second;
    names.append(scene.PathOf(scene.IdAt(rows[i].first)));
    found.mutable_data()[i] = r.found;
    distance.mutable_data()[i] = r.found ? r.distance : std::numeric_limits<double>::infinity();
    const Vec3 a = r.found ? r.p1 : Vec3{NAN, NAN, NAN}, b = r.found ? r.p2 : Vec3{NAN, NAN, NAN};
    double* x = p1.mutable_data() + 3 * i;
    double* y = p2.mutable_data() + 3 * i;
    x[0] = a.x, x[1] = a.y, x[2] = a.z, y[0] = b.x, y[1] = b.y, y[2] = b.z;
  }
  py::dict out;
  out["names"] = names;
  out["found"] = found;
  out["distance"] = distance;
  out["p1"] = p1;
  out["p2"] = p2;
  return out;
}

py::dict Collisions(const Scene& scene) {
  const auto rows = LiveRows<collision::CollisionRow>(scene, "collision");
  const auto k = static_cast<py::ssize_t>(rows.size());
  py::list names;
  py::array_t<bool> colliding(k);
  py::array_t<int64_t> offsets(k + 1);
  std::vector<Vec3> points;
  for (size_t i = 0; i < rows.size(); ++i) {
    const collision::CollisionRow& r = *rows[i].second;
    names.append(scene.PathOf(scene.IdAt(rows[i].first)));
    colliding.mutable_data()[i] = r.colliding;
    offsets.mutable_data()[i] = static_cast<int64_t>(points.size());
    points.insert(points.end(), r.contact_points.begin(), r.contact_points.end());
  }
  offsets.mutable_data()[k] = static_cast<int64_t>(points.size());
  py::dict out;
  out["names"] = names;
  out["colliding"] = colliding;
  out["offsets"] = offsets;
  out["points"] = Points(points);
  return out;
}

}  // namespace swarmsim::python
