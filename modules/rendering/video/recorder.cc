#include "modules/rendering/video/recorder.h"

#include <pthread.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <mutex>
#include <new>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/start_thread.h"
#include "framework/world.h"
#include "modules/paint/png_io.h"
#include "modules/rendering/geometry.h"
#include "modules/rendering/objects.h"
#include "modules/rendering/render.h"
#include "modules/rendering/video/frame_geometry.h"
#include "modules/rendering/video/video_writer.h"

namespace swarmsim::video {

namespace {

constexpr int kMaxSide = 8192;  // pixels, the renderer's limit
constexpr int kMaxVideoSide = 4096;
constexpr size_t kMaxQueued = 4;       // frames waiting for the recorder's thread
constexpr size_t kMessageRoom = 1024;  // bytes of a failure's message the thread keeps

std::string Size(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

std::string Number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// `file` relative to `dir` when it lies inside, else absolute.
std::string RelativeTo(const std::filesystem::path& file, const std::filesystem::path& dir) {
  const std::filesystem::path f = std::filesystem::absolute(file).lexically_normal();
  if (dir.empty()) return f.string();
  const std::filesystem::path r = f.lexically_relative(std::filesystem::absolute(dir));
  if (r.empty() || *r.begin() == "..") return f.string();
  return r.string();
}

// One frame for the recorder's thread: the scene's triangles as they were
// at `step`, the view, and what to write.
struct Job {
  rendering::DrawList list;
  std::vector<uint8_t> closed;  // per item of `list`: 1 for a closed primitive (box, cylinder, ...)
  std::vector<uint8_t> paint;   // the paint layer's pixels then (list.floor points here)
  rendering::View view;
  rendering::DrawOptions options;
  int64_t step = 0;
  bool snapshot = false;
  bool video = false;
};

// How a camera object draws: a vision sensor with its own floor and
// background (not its detectable set: the recorder shows everything);
// a camera, the defaults.
rendering::DrawOptions OptionsOf(const Scene& scene, std::string_view path) {
  rendering::DrawOptions options;
  const ObjectId id = scene.FindObject(path);
  ObjectType sensor{};
  if (id.IsNull() || !scene.FindType("vision_sensor", &sensor)) return options;
  const uint32_t slot = scene.SlotOf(id);
  if (scene.type_at(slot) != sensor) return options;
  const auto& rows = static_cast<const Rows<rendering::VisionSensorRow>&>(*scene.rows(sensor));
  const rendering::VisionSensorRow& row = rows.rows[scene.row_at(slot)];
  options.floor = row.floor;
  options.background = row.background;
  return options;
}

// The view of the camera or vision sensor at `path`; nullopt and *why
// (what is wrong with the name, without the scene's list of names) when
// there is none.
std::optional<rendering::View> FindCamera(const World& world, const std::string& path,
                                          std::string* why) {
  try {
    if (world.scene().FindObject(path).IsNull()) {
      *why = "no object has that path";
      return std::nullopt;
    }
    return rendering::CameraView(world, path, why);
  } catch (const Error& e) {  // a malformed path
    *why = e.what();
    return std::nullopt;
  }
}

}  // namespace

int64_t FramePeriod(double fps, double time_step) {
  if (!(fps > 0) || !(time_step > 0)) return 1;
  const double steps = 1 / (fps * time_step);
  return steps < 1e15 ? std::max<int64_t>(1, std::llround(steps)) : int64_t{1000000000000000};
}

std::vector<std::string> CameraPaths(const Scene& scene) {
  std::vector<std::string> paths;
  ObjectType camera{}, sensor{};
  const bool has_camera = scene.FindType("camera", &camera);
  const bool has_sensor = scene.FindType("vision_sensor", &sensor);
  for (uint32_t slot = 0; slot < scene.slot_count(); ++slot) {
    if (!scene.alive_at(slot)) continue;
    const ObjectType t = scene.type_at(slot);
    if ((has_camera && t == camera) || (has_sensor && t == sensor))
      paths.push_back(scene.PathOf(scene.IdAt(slot)));
  }
  return paths;
}

struct Recorder::Impl {
  RecorderSettings settings;
  std::string view_name;  // "the arena view", "camera /cam"
  int width = 0, height = 0;
  int64_t video_period = 0;  // steps between frames; 0: no video
  double video_rate = 0;     // frames per second of video (and of simulated time)
  std::unique_ptr<VideoWriter> writer;
  std::vector<std::string> notes;
  rendering::View arena;
  int64_t frames_queued = 0, snapshots_queued = 0;

  // Shared with the recorder's thread.
  mutable std::mutex mutex;
  std::condition_variable wake;  // a job, or the end
  std::condition_variable room;  // a job done
  std::deque<Job> queue;
  std::vector<Job> spare;  // jobs done, to fill again (their arrays keep their capacity)
  bool closing = false;
  bool finished = false;
  std::string error;  // the first failure
  std::vector<OutputFile> snapshots;
  int64_t frames_written = 0;
  // Set when a write failed: the frames the file holds, read back from it.
  std::optional<int64_t> frames_in_file;
  std::thread thread;

  // The recorder's thread. Nothing may escape it (an exception there ended
  // the process: std::terminate, exit 134): out of memory, a job fails
  // with a fixed message written into room taken before the jobs, and the
  // thread goes on draining the queue, so Capture and Finish never wait
  // for ever.
  void Work() {
    static constexpr const char* kOutOfMemory =
        "out of memory while drawing or writing a frame (the machine, a ulimit or --max-memory "
        "gave no more)";
    Image image;  // this thread's frame
    std::string what, path;
    what.reserve(kMessageRoom);
    path.reserve(64);
    std::unique_lock lock(mutex);
    for (;;) {
      wake.wait(lock, [&] { return closing || !queue.empty(); });
      if (queue.empty()) return;
      Job job = std::move(queue.front());
      const bool failed = !error.empty();
      lock.unlock();
      what.clear();
      path.clear();
      if (!failed) {
        try {
          DropHiddenFaces(job.view, job.closed, &job.list);
          rendering::Draw(job.list, job.view, job.options, &image);
          if (job.snapshot) {
            char name[64];
            std::snprintf(name, sizeof name, "snapshots/step_%06lld.png",
                          static_cast<long long>(job.step));
            path.assign(name);
            what.assign("--snapshot-every: ");
            paint::WritePng(settings.out_dir / path, image.width, image.height, image.rgb);
          }
          if (job.video) {
            what.assign("--video: ");
            writer->Write(image);
          }
          what.clear();
        } catch (const std::bad_alloc&) {
          what.assign(kOutOfMemory);
        } catch (const std::exception& e) {
          // Within the room taken: a message longer than that is cut.
          const std::string_view text = e.what();
          what.append(text.substr(0, what.capacity() - what.size()));
        }
      }
      lock.lock();
      if (!failed && what.empty()) {
        try {
          if (job.snapshot)
            snapshots.push_back(
                {"snapshot", path, "step " + std::to_string(job.step) + ", " + view_name});
          if (job.video) ++frames_written;
        } catch (const std::bad_alloc&) {
          what.assign(kOutOfMemory);
        }
      }
      if (!what.empty() && error.empty()) error.assign(what);  // within error's room
      queue.pop_front();
      spare.push_back(std::move(job));  // room for every job taken at the start
      room.notify_all();
    }
  }

  // Draws the frame of the world's current step, if one is due, and hands it
  // to the recorder's thread.
  void Capture(const World& world) {
    const int64_t step = world.step_count();
    const bool snapshot = settings.snapshot_every > 0 && step % settings.snapshot_every == 0;
    const bool video = video_period > 0 && step % video_period == 0;
    if (!snapshot && !video) return;
    Job job;
    {
      std::unique_lock lock(mutex);
      if (!error.empty()) throw Error(error);
      room.wait(lock, [&] { return queue.size() < kMaxQueued; });
      if (!spare.empty()) {
        job = std::move(spare.back());
        spare.pop_back();
      }
    }
    job.view = arena;
    if (!settings.camera.empty()) {
      std::string why;
      const std::optional<rendering::View> camera = FindCamera(world, settings.camera, &why);
      if (!camera) throw Error("--camera '" + settings.camera + "': " + why);
      job.view = *camera;
      job.view.width = width;
      job.view.height = height;
      job.view.depth = false;
      job.options = OptionsOf(world.scene(), settings.camera);
    }
    // A view from above keeps LEDs at least 3 pixels across, as Render does.
    const double pixel =
        job.view.orthographic ? job.view.ortho_width / std::max(1, job.view.width) : 0;
    rendering::BuildDrawList(world, SegmentsFor(job.view), &job.list, 1.5 * pixel, settings.rays);
    MarkClosed(world.scene(), job.list, &job.closed);
    // The paint layer changes in the next steps: the frame gets a copy.
    rendering::FloorLayer& floor = job.list.floor;
    if (floor.present && floor.rgb != nullptr) {
      job.paint.assign(floor.rgb, floor.rgb + static_cast<size_t>(floor.width) * floor.height * 3);
      floor.rgb = job.paint.data();
    }
    job.step = step;
    job.snapshot = snapshot;
    job.video = video;
    frames_queued += video;
    snapshots_queued += snapshot;
    {
      const std::lock_guard lock(mutex);
      queue.push_back(std::move(job));
    }
    wake.notify_one();
  }

  void Finish() {
    {
      const std::lock_guard lock(mutex);
      if (finished) return;
      finished = true;
      closing = true;
    }
    wake.notify_one();
    if (thread.joinable()) thread.join();
    // A run that ended before its world's first frame (the start failed)
    // leaves no video of no frames and no empty snapshots folder.
    std::error_code ec;
    if (writer && frames_queued == 0) {
      writer.reset();
      std::filesystem::remove(settings.video, ec);
    }
    if (settings.snapshot_every > 0 && snapshots_queued == 0)
      std::filesystem::remove(settings.out_dir / "snapshots", ec);  // only if empty
    if (writer) {
      try {
        writer->Finish();
      } catch (const std::exception& e) {
        if (error.empty()) error = std::string("--video: ") + e.what();
      }
      // A write that failed (a full disk, ulimit -f) may have cut the file
      // short of the frames encoded: what it holds is counted back from it,
      // for the outputs' line (the frames encoded overstated it).
      if (!error.empty()) {
        int64_t held = 0;
        try {
          VideoReader reader(settings.video);
          Image frame;
          while (held < frames_written && reader.Next(&frame)) ++held;
        } catch (const std::exception&) {  // no frame can be read from it
        }
        const std::lock_guard lock(mutex);
        frames_in_file = held;
      }
    }
    if (!error.empty()) throw Error(error);
  }

  // The outputs' words for the frames: "81 frames", or with a failed write
  // "70 frames (of 81 drawn: its writing failed)".
  std::string FramesText() const {
    std::string text = std::to_string(frames_in_file.value_or(frames_written)) + " frames";
    if (frames_in_file && *frames_in_file < frames_written)
      text += " (of " + std::to_string(frames_written) + " drawn: its writing failed)";
    return text;
  }
};

Recorder::Recorder(World* world, const RecorderSettings& settings)
    : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.settings = settings;
  const bool video = !settings.video.empty();
  if (settings.snapshot_every < 0) throw Error("--snapshot-every must be >= 1");
  if (settings.snapshot_every > 0 && settings.out_dir.empty())
    throw Error("--snapshot-every writes DIR/snapshots/step_NNNNNN.png and needs --out DIR");
  // The view: a camera's, at its resolution, or the arena's at 640x480.
  r.width = settings.width > 0 ? settings.width : 640;
  r.height = settings.height > 0 ? settings.height : 480;
  r.view_name = "the arena seen from above";
  if (!settings.camera.empty()) {
    std::string why;
    const std::optional<rendering::View> camera = FindCamera(*world, settings.camera, &why);
    if (!camera) {
      const std::vector<std::string> cameras = CameraPaths(world->scene());
      std::string message = "--camera '" + settings.camera + "': " + why + "; ";
      if (cameras.empty()) {
        message +=
            "this world has no camera or vision sensor (leave --camera out for the arena "
            "seen from above)";
      } else {
        message += "its cameras and vision sensors: ";
        const size_t shown = std::min<size_t>(cameras.size(), 10);
        for (size_t i = 0; i < shown; ++i) message += (i ? ", " : "") + cameras[i];
        if (cameras.size() > shown)
          message += " and " + std::to_string(cameras.size() - shown) + " more";
      }
      throw Error(message);
    }
    if (settings.width <= 0) r.width = camera->width;
    if (settings.height <= 0) r.height = camera->height;
    r.view_name = "camera " + settings.camera;
  }
  const int max_side = video ? kMaxVideoSide : kMaxSide;
  if (r.width < 1 || r.height < 1 || r.width > max_side || r.height > max_side)
    throw Error((settings.width > 0 ? "--video-size " : "camera '" + settings.camera + "' of ") +
                Size(r.width, r.height) + ": " + (video ? "a video's" : "an image's") +
                " sides are 1.." + std::to_string(max_side) + " pixels" +
                (settings.width > 0 ? "" : " (pass --video-size)"));
  if (video && (r.width % 2 != 0 || r.height % 2 != 0)) {
    const int w = r.width + r.width % 2, h = r.height + r.height % 2;
    r.notes.push_back("H.264 takes even sizes: frames are " + Size(w, h) + ", not " +
                      Size(r.width, r.height));
    r.width = w;
    r.height = h;
  }
  // The video: a frame every round(1 / (fps dt)) steps.
  if (video) {
    // FFmpeg refuses a frame lasting ~10^6 s (the run went on, then the video
    // failed); past 10,000 frames per simulated second every step is a frame.
    if (!(settings.video_fps >= 1e-3 && settings.video_fps <= 1e4))
      throw Error("--video-fps must be from 0.001 to 10000 frames per simulated second, got " +
                  Number(settings.video_fps));
    const double dt = world->settings().time_step;
    r.video_period = FramePeriod(settings.video_fps, dt);
    r.video_rate = 1 / (static_cast<double>(r.video_period) * dt);
    if (std::abs(r.video_rate - settings.video_fps) > 0.005 * settings.video_fps)
      r.notes.push_back(
          "--video-fps " + Number(settings.video_fps) + ": with a time step of " + Number(dt) +
          " s the video gets a frame every " +
          (r.video_period == 1 ? std::string("step") : std::to_string(r.video_period) + " steps") +
          ", " + Number(std::round(r.video_rate * 100) / 100) +
          " frames per simulated second (it plays in real time)");
    VideoSettings vs;
    vs.width = r.width;
    vs.height = r.height;
    vs.fps = r.video_rate;
    try {
      r.writer = std::make_unique<VideoWriter>(settings.video, vs);
    } catch (const Error& e) {
      throw Error(std::string("--video: ") + e.what());
    }
  }
  // What fails from here on (no snapshots folder, no OSMesa, no thread)
  // leaves no video file of no frames behind.
  struct DropVideo {
    Impl* r;
    const std::filesystem::path* file;
    ~DropVideo() {
      if (r == nullptr || r->writer == nullptr) return;
      r->writer.reset();
      std::error_code ec;
      std::filesystem::remove(*file, ec);
    }
  } drop_video{&r, &settings.video};
  if (settings.snapshot_every > 0) {
    std::error_code ec;
    std::filesystem::create_directories(settings.out_dir / "snapshots", ec);
    if (ec)
      throw Error("--snapshot-every: cannot create '" + (settings.out_dir / "snapshots").string() +
                  "': " + ec.message());
  }
  // A machine without OSMesa hears it now, before the run.
  {
    rendering::View probe;
    probe.width = probe.height = 2;
    Image image;
    rendering::Draw(rendering::DrawList{}, probe, rendering::DrawOptions{}, &image);
  }
  // Room the recorder's thread fills without asking for memory (Work).
  r.error.reserve(kMessageRoom);
  r.spare.reserve(kMaxQueued + 2);
  r.thread = StartThread("the video's and snapshots' recorder", [&r] { r.Work(); });
  drop_video.r = nullptr;
  pthread_setname_np(r.thread.native_handle(), "recorder");  // in top and perf
}

Recorder::~Recorder() {
  try {
    impl_->Finish();
  } catch (const std::exception&) {  // reported by an earlier Finish, or nobody asked
  }
}

void Recorder::Start(World* world) {
  Impl& r = *impl_;
  if (r.settings.camera.empty()) r.arena = rendering::ArenaView(*world, r.width, r.height);
  r.Capture(*world);
}

void Recorder::Record(const World& world, std::vector<MetricSample>* /*out*/) {
  impl_->Capture(world);
}

void Recorder::WriteOutputs(const std::filesystem::path& /*dir*/) const { Finish(); }

void Recorder::Finish() const { impl_->Finish(); }

void Recorder::ListOutputs(std::vector<OutputFile>* out) const {
  const Impl& r = *impl_;
  const std::lock_guard lock(r.mutex);
  out->insert(out->end(), r.snapshots.begin(), r.snapshots.end());
  if (r.writer)
    out->push_back({"video", RelativeTo(r.settings.video, r.settings.out_dir),
                    "H.264 " + Size(r.width, r.height) + ", " +
                        Number(std::round(r.video_rate * 100) / 100) + " frames/s, " +
                        r.FramesText() + ", " + r.view_name});
}

std::string Recorder::ProgressNote() const {
  const Impl& r = *impl_;
  std::string note;
  if (r.writer) note = "video " + std::to_string(r.frames_queued) + " frames";
  if (r.settings.snapshot_every > 0)
    note += (note.empty() ? "" : ", ") + std::to_string(r.snapshots_queued) + " snapshots";
  return note;
}

const std::vector<std::string>& Recorder::notes() const { return impl_->notes; }

std::string Recorder::VideoLine() const {
  const Impl& r = *impl_;
  if (!r.writer) return "";
  const std::lock_guard lock(r.mutex);
  return r.settings.video.string() + ": " + r.FramesText() + ", " + Size(r.width, r.height) + ", " +
         Number(std::round(r.video_rate * 100) / 100) + " frames/s, " + r.view_name;
}

ModuleDescriptor RecorderModule() {
  return {{"output", "recorder", "1.0",
           "PNG snapshots and H.264 video of a view every N steps (swarmsim run --snapshot-every, "
           "--video)"},
          PhaseBit(Phase::kRecord),
          300,
          /*every_world=*/false,
          [](World* world, const void* config) -> std::unique_ptr<Module> {
            if (config == nullptr) throw Error("the recorder module needs its settings");
            return std::make_unique<Recorder>(world, *static_cast<const RecorderSettings*>(config));
          }};
}

void Register(ModuleRegistry* registry) {
  registry->RegisterModule(RecorderModule());
  auto recorder = std::make_shared<ViewRecorderDescriptor>();
  recorder->add = [](World* world, const ViewRecorderSettings& settings) -> ViewRecorder* {
    return static_cast<Recorder*>(world->AddModule("recorder", &settings));
  };
  registry->RegisterViewRecorder(std::move(recorder));
}

}  // namespace swarmsim::video
