// The graph module's instance (internal to modules/graphs).
//
// Each graph object gets a series when the module first sees it (at the
// start, or after a copy): its settings, its streams' objects resolved from
// the graph, and a buffer of samples (time, then one value per stream).
// Samples are taken at the start (time 0) and in the record phase of every
// step whose count is a multiple of the graph's `every`, robots in
// parallel (each writes only its own series). A removed graph's series is
// kept, so a run's outputs hold every graph that existed. Nothing of it
// changes the future: it is not in the state hash.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "framework/module.h"
#include "modules/graphs/rows.h"

namespace swarmsim::graphs {

inline constexpr const char* kModuleName = "graphs";
inline constexpr uint32_t kNoSlot = std::numeric_limits<uint32_t>::max();
// PNGs drawn per run at most (CSV files have no limit): past it the
// summary says which graphs have none.
inline constexpr int kMaxPngs = 200;

// The object a stream of the graph `graph` reads, checked for the stream's
// kind (a joint for `joint`, ...); null, with *problem set, if none.
ObjectId ResolveStream(const Scene& scene, ObjectId graph, const StreamSpec& stream,
                       std::string* problem);

// One graph's recording.
struct Series {
  uint64_t id = 0;                // the graph object's handle (ObjectId::ToInteger)
  std::string path;               // its scene path, "/footbot#3/trace"
  std::string file;               // file name stem under graphs/, "footbot#3/trace" (unique)
  GraphRow settings;              // as the graph had them when the series began
  int instance = -1;              // its robot, -1 for the scene
  bool alive = true;              // the graph is still in the scene
  uint32_t row = 0;               // its row in the graph table (while alive)
  std::vector<uint32_t> sources;  // the slot each stream reads (kNoSlot: none; streams)
  // Samples, (1 + streams) values each: a ring of at most settings.buffer.
  std::vector<double> data;
  size_t first = 0;     // the oldest sample
  size_t count = 0;     // samples kept
  int64_t dropped = 0;  // samples not kept (a full buffer)

  size_t width() const { return settings.streams.size() + 1; }
  // Sample i (0: the oldest kept).
  const double* sample(size_t i) const { return &data[((first + i) % count_capacity()) * width()]; }
  size_t count_capacity() const { return data.size() / width(); }
};

class GraphModule final : public Module {
 public:
  explicit GraphModule(World* world) : world_(world) {}
  void Start(World* world) override;
  void Record(const World& world, std::vector<MetricSample>* out) override;
  // graphs/<path>.csv for every graph, and .png (gnuplot) for the first kMaxPngs.
  void WriteOutputs(const std::filesystem::path& dir) const override;
  void ListOutputs(std::vector<OutputFile>* out) const override;
  // Snapshots (framework/world_state.h): a graph's series is not saved, so a
  // world with graphs is refused; without them the module is idle.
  bool SaveState(const World& world, StateWriter* out) const override;

  // The series of the graph `id`, or null (scripts' reads).
  const Series* Find(ObjectId id) const;

 private:
  void Refresh(Scene* scene);
  void Sample(Scene* scene, Series* series, double time);

  World* world_;
  bool have_type_ = false;
  ObjectType type_{};
  uint64_t version_ = UINT64_MAX;                // the scene structure the lists follow
  std::vector<std::unique_ptr<Series>> series_;  // creation order
  std::unordered_map<uint64_t, size_t> by_id_;   // graph handle -> series
  std::set<std::string> files_;                  // file stems taken
  std::vector<std::vector<uint32_t>> by_robot_;  // live series by robot, the scene's last
  mutable std::vector<OutputFile> written_;      // what WriteOutputs wrote
};

}  // namespace swarmsim::graphs
