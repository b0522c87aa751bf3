#include "swarm/record/chunk_writer.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>
#include <xxhash.h>
#include <zstd.h>

#include <cerrno>
#include <cstring>
#include <new>

#include "framework/error.h"
#include "framework/start_thread.h"
#include "swarm/record/format.h"

namespace swarmsim::record {
namespace {

// Step records the simulation may run ahead of the file by.
constexpr size_t kMaxQueued = 8;

// A chunk refused for its size, or one that could not be written and was
// cut off again (a full disk): the file is still whole.
struct ChunkTooLarge : Error {
  using Error::Error;
};

const char* ChunkName(uint8_t kind) {
  switch (static_cast<ChunkKind>(kind)) {
    case ChunkKind::kHeader: return "header";
    case ChunkKind::kScene: return "scene";
    case ChunkKind::kKeyframe: return "keyframe";
    case ChunkKind::kDelta: return "step record";
    case ChunkKind::kEnd: return "end";
    case ChunkKind::kLinks: return "links chunk";
  }
  return "chunk";
}

std::string Size(uint64_t bytes) {
  if (bytes < (uint64_t{1} << 20)) return std::to_string(bytes) + " bytes";
  return std::to_string((bytes + (uint64_t{1} << 20) - 1) >> 20) + " MiB";
}

// Fills in a chunk's header before its stored payload (FORMAT.md "Chunks").
void FillChunkHeader(uint8_t kind, uint32_t step, size_t stored, size_t raw, uint8_t* h) {
  std::memcpy(h, kMagic, 4);
  h[4] = kind;
  h[5] = 0;
  h[6] = h[7] = 0;
  const auto put32 = [](uint8_t* at, uint32_t v) {
    for (int i = 0; i < 4; ++i) at[i] = static_cast<uint8_t>(v >> (8 * i));
  };
  put32(h + 8, step);
  put32(h + 12, static_cast<uint32_t>(stored));
  put32(h + 16, static_cast<uint32_t>(raw));
  put32(h + 20, XXH32(h + kChunkHeaderSize, stored, 0));
}

// Appends little-endian values to a byte buffer.
class Out {
 public:
  explicit Out(std::vector<uint8_t>* data) : data_(data) { data_->clear(); }
  template <typename T>
  void Put(T value) {
    const size_t at = data_->size();
    data_->resize(at + sizeof(T));
    std::memcpy(data_->data() + at, &value, sizeof(T));
  }
  template <typename T>
  void PutArray(const std::vector<T>& values) {
    const size_t at = data_->size();
    data_->resize(at + values.size() * sizeof(T));
    if (!values.empty()) std::memcpy(data_->data() + at, values.data(), values.size() * sizeof(T));
  }
  void PutBytes(const void* p, size_t n) {
    const auto* b = static_cast<const uint8_t*>(p);
    data_->insert(data_->end(), b, b + n);
  }
  void Pad(size_t alignment) {
    while (data_->size() % alignment != 0) data_->push_back(0);
  }
  // Ascending ids as differences (FORMAT.md), after their count.
  void PutIds(const std::vector<uint32_t>& ids) {
    Put<uint32_t>(static_cast<uint32_t>(ids.size()));
    uint32_t last = 0;
    for (const uint32_t id : ids) {
      Put<uint32_t>(id - last);
      last = id;
    }
  }

 private:
  std::vector<uint8_t>* data_;
};

}  // namespace

struct ChunkWriter::Job {
  uint8_t kind = 0;
  uint32_t step = 0;
  std::string text;                    // JSON chunks
  std::unique_ptr<SceneLists> lists;   // scene chunks
  std::unique_ptr<StepSnapshot> snap;  // step records
};

ChunkWriter::ChunkWriter(const std::filesystem::path& path, int zstd_level, uint32_t max_raw_bytes)
    : path_(path), level_(zstd_level), max_raw_bytes_(max_raw_bytes) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw Error("cannot create " + path.string() + ": " + std::strerror(errno));
  cctx_ = ZSTD_createCCtx();
  error_.reserve(kErrorRoom);
  try {
    thread_ = StartThread("the recording's writer", [this] { Run(); });
  } catch (const Error&) {  // no destructor runs: what the constructor took goes here
    ZSTD_freeCCtx(static_cast<ZSTD_CCtx*>(cctx_));
    ::close(fd_);
    std::error_code ec;
    std::filesystem::remove(path_, ec);  // empty
    throw;
  }
}

ChunkWriter::~ChunkWriter() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
  ZSTD_freeCCtx(static_cast<ZSTD_CCtx*>(cctx_));
  ::close(fd_);
}

void ChunkWriter::Push(std::unique_ptr<Job> job) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return queue_.size() < kMaxQueued || !error_.empty(); });
  if (!error_.empty() && !(file_whole_ && job->kind == static_cast<uint8_t>(ChunkKind::kEnd)))
    throw Error(error_);
  queue_.push_back(std::move(job));
  changed_.notify_all();
}

void ChunkWriter::AddJson(uint8_t kind, uint32_t step, std::string text) {
  auto job = std::make_unique<Job>();
  job->kind = kind;
  job->step = step;
  job->text = std::move(text);
  Push(std::move(job));
}

void ChunkWriter::AddScene(uint32_t step, std::string text, SceneLists lists) {
  auto job = std::make_unique<Job>();
  job->kind = static_cast<uint8_t>(ChunkKind::kScene);
  job->step = step;
  job->text = std::move(text);
  job->lists = std::make_unique<SceneLists>(std::move(lists));
  Push(std::move(job));
}

void ChunkWriter::AddStep(std::unique_ptr<StepSnapshot> step) {
  auto job = std::make_unique<Job>();
  job->kind = static_cast<uint8_t>(step->keyframe ? ChunkKind::kKeyframe : ChunkKind::kDelta);
  job->step = step->step;
  job->snap = std::move(step);
  Push(std::move(job));
}

std::unique_ptr<StepSnapshot> ChunkWriter::TakeSnapshot() {
  {
    const std::lock_guard lock(mutex_);
    if (!spare_.empty()) {
      std::unique_ptr<StepSnapshot> s = std::move(spare_.back());
      spare_.pop_back();
      return s;
    }
  }
  return std::make_unique<StepSnapshot>();
}

void ChunkWriter::Flush() {
  std::unique_lock lock(mutex_);
  // After a failure to write, nothing more will be; after a refused chunk,
  // the end chunk may be on its way.
  changed_.wait(lock,
                [&] { return (queue_.empty() && !busy_) || (!error_.empty() && !file_whole_); });
  if (!error_.empty()) throw Error(error_);
}

uint64_t ChunkWriter::bytes_written() const {
  const std::lock_guard lock(mutex_);
  return bytes_;
}

uint64_t ChunkWriter::step_records_written() const {
  const std::lock_guard lock(mutex_);
  return records_written_;
}

void ChunkWriter::Run() {
  // Below the simulation's threads: on few cores, compressing waits for
  // their idle moments rather than taking a core from a parallel phase.
  setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 10);
  for (;;) {
    std::unique_ptr<Job> job;
    bool failed = false;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] { return !queue_.empty() || stopping_; });
      if (queue_.empty()) return;  // stopping, everything written
      job = std::move(queue_.front());
      queue_.pop_front();
      busy_ = true;
      // After a failure, nothing more; but the end chunk after a chunk
      // refused for its size (the file is whole).
      failed =
          !error_.empty() && !(file_whole_ && job->kind == static_cast<uint8_t>(ChunkKind::kEnd));
    }
    changed_.notify_all();
    std::string error;
    bool whole = true;
    bool no_memory = false;
    try {
      if (!failed) Write(job.get());
    } catch (const ChunkTooLarge& e) {
      error = e.what();
    } catch (const std::bad_alloc&) {
      no_memory = true;  // (the message, composed, could need memory)
    } catch (const std::exception& e) {
      error = e.what();
      whole = false;
    }
    {
      const std::lock_guard lock(mutex_);
      busy_ = false;
      if (no_memory) {
        whole = out_of_memory_;  // cut back to whole chunks, or not
        // Into room reserved for it: no allocation.
        if (error_.empty())
          error_.assign("out of memory while writing the recording: its later steps are left out");
      }
      if (!whole) file_whole_ = false;
      if (!error.empty() && error_.empty()) error_ = error;
      if (job->snap && spare_.size() < kMaxQueued) spare_.push_back(std::move(job->snap));
    }
    changed_.notify_all();
  }
}

void ChunkWriter::Write(Job* job) {
  // A job that cannot be written whole (ENOSPC partway) is cut off again, so
  // that the file ends with whole chunks and the end chunk may still follow
  // (it was left with half a chunk and no end: "the run was killed").
  uint64_t start = 0;
  {
    const std::lock_guard lock(mutex_);
    start = bytes_;
    out_of_memory_ = false;
  }
  try {
    WriteJob(job);
  } catch (const ChunkTooLarge&) {
    throw;
  } catch (const Error& e) {
    if (::ftruncate(fd_, static_cast<off_t>(start)) != 0 ||
        ::lseek(fd_, static_cast<off_t>(start), SEEK_SET) != static_cast<off_t>(start))
      throw;
    const std::lock_guard lock(mutex_);
    bytes_ = start;
    throw ChunkTooLarge(e.what());
  } catch (const std::bad_alloc&) {
    // Out of memory compressing it: cut off too, so that the end chunk
    // (small, its buffers already there) may still follow; Run says why
    // in words it composes without memory.
    if (::ftruncate(fd_, static_cast<off_t>(start)) != 0 ||
        ::lseek(fd_, static_cast<off_t>(start), SEEK_SET) != static_cast<off_t>(start))
      throw;
    const std::lock_guard lock(mutex_);
    bytes_ = start;
    out_of_memory_ = true;
    throw;
  }
  if (job->snap) {
    const std::lock_guard lock(mutex_);
    ++records_written_;
  }
}

void ChunkWriter::WriteJob(Job* job) {
  if (job->lists) {
    lists_ = *job->lists;
    pose_.assign(lists_.object_count, {});
    color_.assign(lists_.object_count, 0);
    reading_.assign(lists_.object_count, 0);
  }
  if (job->snap) {
    StepSnapshot& snap = *job->snap;
    Encode(&snap, &payload_);
    WriteChunk(job->kind, job->step, payload_.data(), payload_.size());
    if (snap.links) {
      // The links chunk (FORMAT.md "Links chunk"), complete at every record.
      Out out(&payload_);
      out.Put<uint32_t>(snap.record);
      out.PutIds(snap.link_from);
      out.PutArray(snap.link_to);
      WriteChunk(static_cast<uint8_t>(ChunkKind::kLinks), job->step, payload_.data(),
                 payload_.size());
      snap.link_from.clear();
      snap.link_to.clear();
    }
  } else {
    WriteChunk(job->kind, job->step, job->text.data(), job->text.size());
  }
}

// Keeps the snapshot's state as the previous one (swapped: the snapshot goes
// back to the spares with the old arrays, overwritten when it is next filled).
void ChunkWriter::Encode(StepSnapshot* snap, std::vector<uint8_t>* payload) {
  const StepSnapshot& s = *snap;
  Out out(payload);
  const bool key = s.keyframe;
  out.Put<double>(s.time);
  out.Put<uint32_t>(s.record);
  out.Put<uint32_t>(0);
  // Poses: every one in a keyframe, else those whose integers changed, as differences.
  std::vector<uint32_t> ids;
  for (uint32_t id = 0; id < s.pose.size(); ++id)
    if (key || !(s.pose[id] == pose_[id])) ids.push_back(id);
  out.PutIds(ids);
  const auto put = [&](auto field) {
    for (const uint32_t id : ids) {
      using T = std::remove_cvref_t<decltype(s.pose[id].*field)>;
      using U = std::make_unsigned_t<T>;
      const T now = s.pose[id].*field;
      out.Put<U>(key ? static_cast<U>(now)
                     : static_cast<U>(static_cast<U>(now) - static_cast<U>(pose_[id].*field)));
    }
  };
  put(&QuantizedPose::x);
  put(&QuantizedPose::y);
  put(&QuantizedPose::z);
  put(&QuantizedPose::qw);
  put(&QuantizedPose::qx);
  put(&QuantizedPose::qy);
  put(&QuantizedPose::qz);
  out.Pad(4);
  // Colours of shapes and LEDs.
  ids.clear();
  for (const uint32_t id : lists_.color_ids)
    if (key || s.color[id] != color_[id]) ids.push_back(id);
  out.PutIds(ids);
  for (const uint32_t id : ids) out.Put<uint32_t>(s.color[id]);
  // Proximity readings.
  ids.clear();
  for (const uint32_t id : lists_.proximity_ids)
    if (key || s.reading[id] != reading_[id]) ids.push_back(id);
  out.PutIds(ids);
  for (const uint32_t id : ids) out.Put<uint16_t>(s.reading[id]);
  out.Pad(4);
  // Paint cells (chosen by the capture).
  out.PutIds(s.paint_cells);
  out.PutArray(s.paint_rgba);
  // Metrics.
  out.Put<uint32_t>(s.first_name);
  out.Put<uint32_t>(static_cast<uint32_t>(s.names.size()));
  for (const std::string& name : s.names) {
    const size_t length = std::min<size_t>(name.size(), 65535);
    out.Put<uint16_t>(static_cast<uint16_t>(length));
    out.PutBytes(name.data(), length);
  }
  out.Pad(4);
  out.Put<uint32_t>(static_cast<uint32_t>(s.samples.size()));
  for (const SampleRow& r : s.samples) out.Put<uint32_t>(r.name);
  for (const SampleRow& r : s.samples) out.Put<int32_t>(r.robot);
  for (const SampleRow& r : s.samples) out.Put<uint32_t>(r.step);
  out.Pad(8);
  for (const SampleRow& r : s.samples) out.Put<double>(r.value);
  pose_.swap(snap->pose);
  color_.swap(snap->color);
  reading_.swap(snap->reading);
  snap->paint_cells.clear();
  snap->paint_rgba.clear();
  snap->names.clear();
  snap->samples.clear();
}

void ChunkWriter::WriteChunk(uint8_t kind, uint32_t step, const void* raw, size_t size) {
  // Nothing a reader would refuse (FORMAT.md "Limits"): the chunks before
  // stay the whole recording.
  if (size > max_raw_bytes_)
    throw ChunkTooLarge(path_.string() + ": the " + ChunkName(kind) + " of step " +
                        std::to_string(step) + " would hold " + Size(size) +
                        " decompressed, past the " + Size(max_raw_bytes_) +
                        " a recording chunk may hold (what readers accept: FORMAT.md, "
                        "\"Limits\"); the recording ends before it. Record fewer objects or "
                        "metric samples (a smaller world, record: every N)");
  const size_t bound = ZSTD_compressBound(size);
  chunk_.resize(kChunkHeaderSize + bound);
  const size_t stored = ZSTD_compressCCtx(
      static_cast<ZSTD_CCtx*>(cctx_), chunk_.data() + kChunkHeaderSize, bound, raw, size, level_);
  if (ZSTD_isError(stored))
    throw Error("cannot compress a chunk of " + path_.string() + ": " + ZSTD_getErrorName(stored));
  chunk_.resize(kChunkHeaderSize + stored);
  FillChunkHeader(kind, step, stored, size, chunk_.data());
  // One write per chunk: a reader (or a kill) never sees half of one but at the end.
  size_t done = 0;
  while (done < chunk_.size()) {
    const ssize_t n = ::write(fd_, chunk_.data() + done, chunk_.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw Error("cannot write " + path_.string() + ": " + std::strerror(n < 0 ? errno : ENOSPC));
    done += static_cast<size_t>(n);
  }
  const std::lock_guard lock(mutex_);
  bytes_ += chunk_.size();
}

std::string EncodeChunkBytes(uint8_t kind, uint32_t step, const std::string& payload) {
  std::string out(kChunkHeaderSize + ZSTD_compressBound(payload.size()), '\0');
  auto* h = reinterpret_cast<uint8_t*>(out.data());
  const size_t stored = ZSTD_compress(h + kChunkHeaderSize, out.size() - kChunkHeaderSize,
                                      payload.data(), payload.size(), 3);
  if (ZSTD_isError(stored)) throw Error(std::string("zstd: ") + ZSTD_getErrorName(stored));
  out.resize(kChunkHeaderSize + stored);
  FillChunkHeader(kind, step, stored, payload.size(), reinterpret_cast<uint8_t*>(out.data()));
  return out;
}

}  // namespace swarmsim::record
