// The recorder's back end (internal to swarm/record): step records encoded
// against the previous one (FORMAT.md "Step records"), compressed and
// appended, one whole chunk per write, on a thread of its own, so that the
// simulation's thread only captures the state.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "swarm/record/format.h"

namespace swarmsim::record {

// A pose in the file's integers: position in kPositionUnit, quaternion in 1/32767.
struct QuantizedPose {  // 20 bytes
  int32_t x, y, z;
  int16_t qw, qx, qy, qz;
  bool operator==(const QuantizedPose&) const = default;
};

struct SampleRow {  // 24 bytes
  uint32_t name;
  int32_t robot;
  uint32_t step;
  double value;
};

// What one step record holds, captured on the simulation's thread.
struct StepSnapshot {
  uint32_t step = 0;
  double time = 0;
  uint32_t record = 0;  // 0, 1, 2, ... in the file
  bool keyframe = false;
  std::vector<QuantizedPose> pose;                // (ids)
  std::vector<uint32_t> color;                    // packed rgba (ids; shapes and LEDs only)
  std::vector<uint16_t> reading;                  // (ids; proximity sensors only)
  std::vector<uint32_t> paint_cells, paint_rgba;  // changed cells (keyframe: every painted one)
  uint32_t first_name = 0;                        // metric names from this id on
  std::vector<std::string> names;
  std::vector<SampleRow> samples;
  // Links (1.2): written as a links chunk after the step record when
  // `links` (the scene has objects whose type declares links): pairs of
  // recorded ids, ascending by `link_from`.
  bool links = false;
  std::vector<uint32_t> link_from, link_to;
};

// The scene's lists the encoder needs, sent with every scene chunk.
struct SceneLists {
  size_t object_count = 0;
  std::vector<uint32_t> color_ids, proximity_ids;  // ascending
};

// Appends chunks to a file from a thread of its own, in the order given.
class ChunkWriter {
 public:
  // Creates (truncates) `path`. Throws swarmsim::Error naming it when it cannot.
  // A chunk whose payload would pass `max_raw_bytes` decompressed (what
  // every reader accepts, FORMAT.md "Limits"; tests lower it) is not
  // written: an error naming it, after which only the end chunk is (the
  // file stays whole and readable).
  ChunkWriter(const std::filesystem::path& path, int zstd_level,
              uint32_t max_raw_bytes = kMaxChunkRawBytes);
  ~ChunkWriter();  // writes what is queued, then stops
  ChunkWriter(const ChunkWriter&) = delete;
  ChunkWriter& operator=(const ChunkWriter&) = delete;

  // A JSON chunk (header, end).
  void AddJson(uint8_t kind, uint32_t step, std::string text);
  // A scene chunk; the step records after it are encoded against `lists`.
  void AddScene(uint32_t step, std::string text, SceneLists lists);
  void AddStep(std::unique_ptr<StepSnapshot> step);
  // A snapshot to fill: one the writer is done with (its arrays keep their
  // room: no allocation per step), or a new one.
  std::unique_ptr<StepSnapshot> TakeSnapshot();
  // Waits until everything queued is written. Throws swarmsim::Error if a
  // chunk could not be written (also from the Add calls, after a failure).
  void Flush();
  uint64_t bytes_written() const;
  // Step records in the file (not those queued, nor one a failure cut off).
  uint64_t step_records_written() const;

 private:
  struct Job;
  void Push(std::unique_ptr<Job> job);
  void Run();
  void Write(Job* job);
  void WriteJob(Job* job);
  void Encode(StepSnapshot* s, std::vector<uint8_t>* out);
  void WriteChunk(uint8_t kind, uint32_t step, const void* raw, size_t size);

  std::filesystem::path path_;
  int fd_ = -1;
  int level_;
  uint32_t max_raw_bytes_;
  void* cctx_ = nullptr;  // ZSTD_CCtx
  std::vector<uint8_t> chunk_, payload_;
  // The writer thread's own: the state at the previous step record.
  SceneLists lists_;
  std::vector<QuantizedPose> pose_;
  std::vector<uint32_t> color_;
  std::vector<uint16_t> reading_;

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::unique_ptr<Job>> queue_;  // at most kMaxQueued
  std::vector<std::unique_ptr<StepSnapshot>> spare_;
  bool busy_ = false, stopping_ = false;
  std::string error_;  // kErrorRoom reserved: an out-of-memory message needs no more
  static constexpr size_t kErrorRoom = 256;
  bool out_of_memory_ = false;  // a job cut back whole after running out
  bool file_whole_ = true;      // after an error: no chunk was cut (the end chunk may follow)
  uint64_t bytes_ = 0;
  uint64_t records_written_ = 0;
  std::thread thread_;
};

// One chunk's bytes with `payload` as its decompressed content.
std::string EncodeChunkBytes(uint8_t kind, uint32_t step, const std::string& payload);

}  // namespace swarmsim::record
