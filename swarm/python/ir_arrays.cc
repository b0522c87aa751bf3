#include "swarm/python/ir_arrays.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "framework/scene.h"
#include "modules/ir_messaging/ir_messaging.h"
#include "swarm/python/sensor_arrays.h"

namespace swarmsim::python {

namespace {

using ir_messaging::IrTransceiverRow;

// The transceivers' rows (IrTransceivers found the type first).
const std::vector<IrTransceiverRow>& RowsOf(const Scene& scene) {
  ObjectType type;
  if (!scene.FindType(ir_messaging::kTypeName, &type))
    throw py::value_error("this world has no IR transceivers");
  return scene.rows<IrTransceiverRow>(type).rows;
}
std::vector<IrTransceiverRow>& RowsOf(Scene* scene) {
  ObjectType type;
  if (!scene->FindType(ir_messaging::kTypeName, &type))
    throw py::value_error("this world has no IR transceivers");
  return scene->rows<IrTransceiverRow>(type).rows;
}

// out[key] if it is an array of T and `shape` (C-contiguous, writeable), else
// a new one stored there.
template <typename T>
py::array_t<T> Reuse(py::dict* out, const char* key, const std::vector<py::ssize_t>& shape) {
  if (out->contains(key)) {
    const py::object o = (*out)[key];
    if (py::isinstance<py::array>(o)) {
      auto a = py::reinterpret_borrow<py::array>(o);
      if (a.dtype().is(py::dtype::of<T>()) && (a.flags() & py::array::c_style) && a.writeable() &&
          a.ndim() == static_cast<py::ssize_t>(shape.size()) &&
          std::equal(shape.begin(), shape.end(), a.shape()))
        return py::reinterpret_borrow<py::array_t<T>>(o);
    }
  }
  py::array_t<T> a(shape);
  (*out)[key] = a;
  return a;
}

}  // namespace

std::vector<uint32_t> IrTransceivers(const Scene& scene, const ModelLayout& layout,
                                     const std::string& name, std::vector<std::string>* who) {
  const DeviceTable table = Devices(scene, layout, ir_messaging::kTypeName);
  const size_t column = DeviceColumn(table, name, "IR transceiver");
  const size_t per_robot = table.names.size();
  std::vector<uint32_t> slots(layout.robots.size());
  for (size_t i = 0; i < layout.robots.size(); ++i) {
    slots[i] = table.slots[i * per_robot + column];
    if (who != nullptr) who->push_back("robot '" + scene.instance(layout.robots[i]).name + "'");
  }
  return slots;
}

py::dict IrMessages(const Scene& scene, const std::vector<uint32_t>& slots, const py::object& out) {
  py::dict dict;
  if (!out.is_none()) {
    if (!py::isinstance<py::dict>(out))
      throw py::type_error("out= is a dict ir_messages() returned, or None");
    dict = py::reinterpret_borrow<py::dict>(out);
  }
  const std::vector<IrTransceiverRow>& rows = RowsOf(scene);
  const size_t n = slots.size();
  size_t m = 0, width = 0;
  for (const uint32_t slot : slots) {
    const IrTransceiverRow& ir = rows[scene.row_at(slot)];
    m += ir.inbox.size();
    for (const auto& message : ir.inbox) width = std::max<size_t>(width, message.data_size);
  }
  const auto sn = static_cast<py::ssize_t>(n), sm = static_cast<py::ssize_t>(m),
             sw = static_cast<py::ssize_t>(width);
  auto offsets = Reuse<int64_t>(&dict, "offsets", {sn + 1});
  auto distance = Reuse<double>(&dict, "distance", {sm});
  auto sender = Reuse<int64_t>(&dict, "sender", {sm});
  auto size = Reuse<int64_t>(&dict, "size", {sm});
  auto data = Reuse<uint8_t>(&dict, "data", {sm, sw});
  auto sent = Reuse<bool>(&dict, "sent", {sn});
  int64_t *o = offsets.mutable_data(), *from = sender.mutable_data(), *bytes = size.mutable_data();
  double* d = distance.mutable_data();
  uint8_t* payload = data.mutable_data();
  bool* went = sent.mutable_data();
  if (m > 0 && width > 0) std::memset(payload, 0, m * width);
  size_t k = 0;
  for (size_t i = 0; i < n; ++i) {
    const IrTransceiverRow& ir = rows[scene.row_at(slots[i])];
    o[i] = static_cast<int64_t>(k);
    went[i] = ir.sent;
    for (const auto& message : ir.inbox) {
      d[k] = message.distance;
      from[k] = scene.IsValid(message.sender) ? scene.instance_of(message.sender) : -1;
      bytes[k] = message.data_size;
      std::copy_n(ir.received.data() + message.data_offset, message.data_size, payload + k * width);
      ++k;
    }
  }
  o[n] = static_cast<int64_t>(k);
  return dict;
}

void SendIrMessages(Scene* scene, const std::vector<uint32_t>& slots,
                    const std::vector<std::string>& who, const py::object& data,
                    const py::object& send) {
  const size_t n = slots.size();
  const auto a = MessageBytes(data, "IR messages");
  if (a.ndim() != 2 || static_cast<size_t>(a.shape(0)) != n || a.shape(1) < 1)
    throw py::value_error("IR messages must have shape (" + std::to_string(n) +
                          ", bytes): one row per robot, at least one byte");
  std::vector<uint8_t> sending(n, 1);
  if (!send.is_none()) {
    const py::array mask = py::module_::import("numpy").attr("asarray")(send);
    if (mask.dtype().kind() != 'b' || mask.ndim() != 1 || static_cast<size_t>(mask.shape(0)) != n)
      throw py::value_error("send= must be (" + std::to_string(n) +
                            ",) booleans: which robots send");
    const auto b = py::cast<py::array_t<bool, py::array::c_style | py::array::forcecast>>(mask);
    for (size_t i = 0; i < n; ++i) sending[i] = b.data()[i] ? 1 : 0;
  }
  std::vector<IrTransceiverRow>& rows = RowsOf(scene);
  const size_t k = static_cast<size_t>(a.shape(1));
  const int64_t* v = a.data();
  for (size_t i = 0; i < n; ++i) {
    if (sending[i] == 0) continue;
    for (size_t j = 0; j < k; ++j)
      if (v[i * k + j] < 0 || v[i * k + j] > 255)
        throw py::value_error("IR messages are bytes, 0..255: " + who[i] + "'s has " +
                              std::to_string(v[i * k + j]));
    const uint32_t payload = rows[scene->row_at(slots[i])].settings->payload_size;
    if (k > payload)
      throw py::value_error("an IR message of " + std::to_string(k) + " bytes, more than " +
                            who[i] + "'s payload_size (" + std::to_string(payload) + " bytes)");
  }
  for (size_t i = 0; i < n; ++i) {
    if (sending[i] == 0) continue;
    IrTransceiverRow& ir = rows[scene->row_at(slots[i])];
    ir.outgoing.resize(k);
    for (size_t j = 0; j < k; ++j) ir.outgoing[j] = static_cast<uint8_t>(v[i * k + j]);
    ir.queued = true;
  }
}

}  // namespace swarmsim::python
