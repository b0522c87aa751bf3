// The run recorder: writes DIR/recording.swrec (FORMAT.md) as a run goes,
// the scene once, then one chunk per recorded step, each written and
// flushed whole. An observer in the record phase, after every registered
// module (swarm metrics, paint, video). Nothing it does changes the world.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "framework/module.h"
#include "swarm/record/format.h"

namespace swarmsim {
class World;
}

namespace swarmsim::record {

struct RecordSettings {
  std::filesystem::path out_dir;          // the file is out_dir/recording.swrec
  int64_t every = 1;                      // a step record every N world steps
  int64_t keyframe_every = 100;           // a keyframe every K step records
  std::string world_file;                 // as given to swarmsim run
  int64_t steps_planned = 0;              // the run's last step: recorded whatever `every` says
  std::vector<std::string> metric_names;  // the world's metrics: entries, known at the start
  int zstd_level = 3;
  // What one chunk may hold, decompressed: what every reader accepts (tests lower it).
  uint32_t max_chunk_raw_bytes = kMaxChunkRawBytes;
};

class RunRecorder final : public Module {
 public:
  // Creates (truncates) the file. Throws swarmsim::Error naming it when it cannot.
  explicit RunRecorder(const RecordSettings& settings);
  ~RunRecorder() override;

  // The header, the scene and the keyframe of step 0.
  void Start(World* world) override;
  void Record(const World& world, std::vector<MetricSample>* out) override;
  // Waits until every step record so far is in the file (the records are
  // compressed and written on a thread of the recorder's own). Throws
  // swarmsim::Error if one could not be written.
  void WriteOutputs(const std::filesystem::path& dir) const override;
  void ListOutputs(std::vector<OutputFile>* out) const override;

  // The end chunk: the run's last step and how it ended ("ok", "error",
  // "interrupted"), then waits until the file is complete; later calls do
  // nothing. Never throws.
  void Finish(int64_t steps, const std::string& status, const std::string& error);
  int64_t step_records() const;
  uint64_t bytes_written() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// One chunk's bytes (header and zstd payload) with `payload` as its
// decompressed content: for tests and tools that make recordings by hand.
std::string EncodeChunk(uint8_t kind, uint32_t step, const std::string& payload);

// Adds a recorder to `world` (not started yet) and returns it (owned by the world).
RunRecorder* AddRecorder(World* world, const RecordSettings& settings);

}  // namespace swarmsim::record
