#include "swarm/python/snapshot.h"

#include "framework/error.h"
#include "framework/state_hash.h"
#include "framework/world.h"
#include "framework/world_state.h"

namespace swarmsim::python {

namespace {

// Then the world's bytes (size first), the metrics, and a checksum of all before it.
constexpr char kMagic[8] = "swpy-1";

uint64_t Checksum(std::string_view bytes) {
  StateHasher hasher;
  hasher.Add(bytes.data(), bytes.size());
  return hasher.Digest();
}

}  // namespace

std::string PackSnapshot(World* world, const MetricMaps& metrics) {
  const std::string state = world->SaveState();
  StateWriter out;
  out.PutBytes(kMagic, sizeof kMagic);
  out.PutString(state);
  out.Put<uint64_t>(metrics.swarm->size());
  for (const auto& [name, value] : *metrics.swarm) {
    out.PutString(name);
    out.Put(value);
  }
  out.Put<uint64_t>(metrics.robots->size());
  for (const auto& [name, values] : *metrics.robots) {
    out.PutString(name);
    out.Put<uint64_t>(values.size());
    for (const auto& [robot, value] : values) {
      out.Put(robot);
      out.Put(value);
    }
  }
  out.Put<uint64_t>(metrics.history->size());
  for (const auto& [name, samples] : *metrics.history) {
    out.PutString(name);
    out.Put<uint64_t>(samples.size());
    for (const auto& [step, value] : samples) {
      out.Put(step);
      out.Put(value);
    }
  }
  out.Put(Checksum(out.bytes()));
  return std::move(out.bytes());
}

void UnpackSnapshot(std::string_view bytes, World* world, const MetricMaps& metrics,
                    const World::Reseed* reseed) {
  if (bytes.size() < sizeof kMagic ||
      bytes.substr(0, sizeof kMagic) != std::string_view(kMagic, sizeof kMagic))
    throw Error("snapshot: these bytes are not a swarmsim World snapshot (" +
                std::to_string(bytes.size()) + " bytes)");
  if (bytes.size() < sizeof kMagic + sizeof(uint64_t))
    throw Error("snapshot: truncated (" + std::to_string(bytes.size()) + " bytes)");
  const std::string_view body = bytes.substr(0, bytes.size() - sizeof(uint64_t));
  uint64_t checksum = 0;
  std::memcpy(&checksum, bytes.data() + body.size(), sizeof checksum);
  if (Checksum(body) != checksum)
    throw Error("snapshot: corrupt or truncated (its checksum does not match its bytes)");
  StateReader in(body.substr(sizeof kMagic));
  const std::string state = in.GetString();
  // The metrics are read first, so that bad bytes change nothing.
  std::map<std::string, double> swarm;
  std::map<std::string, std::map<int, double>> robots;
  std::map<std::string, std::vector<std::pair<int64_t, double>>> history;
  for (uint64_t n = in.GetCount(2 * sizeof(uint64_t)); n > 0; --n) {
    std::string name = in.GetString();
    swarm[std::move(name)] = in.Get<double>();
  }
  for (uint64_t n = in.GetCount(2 * sizeof(uint64_t)); n > 0; --n) {
    std::map<int, double>& values = robots[in.GetString()];
    for (uint64_t k = in.GetCount(sizeof(int) + sizeof(double)); k > 0; --k) {
      const int robot = in.Get<int>();
      values[robot] = in.Get<double>();
    }
  }
  for (uint64_t n = in.GetCount(2 * sizeof(uint64_t)); n > 0; --n) {
    auto& samples = history[in.GetString()];
    samples.resize(in.GetCount(sizeof(int64_t) + sizeof(double)));
    for (auto& [step, value] : samples) {
      step = in.Get<int64_t>();
      value = in.Get<double>();
    }
  }
  if (in.remaining() != 0) in.Fail(std::to_string(in.remaining()) + " bytes left over");
  world->RestoreState(state, reseed);
  *metrics.swarm = std::move(swarm);
  *metrics.robots = std::move(robots);
  *metrics.history = std::move(history);
}

}  // namespace swarmsim::python
