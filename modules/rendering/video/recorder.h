// The recorder module ("recorder", record phase, order 300: after paint):
// every N steps it draws a view of the scene (modules/rendering/render.h:
// the arena from above, or a named camera or vision sensor) and writes PNG
// snapshots (DIR/snapshots/step_000120.png) and/or the frames of an H.264
// video (video_writer.h). Made on request: World::AddModule("recorder",
// &settings), as `swarmsim run --snapshot-every/--video` does.
//
// The simulation's thread collects each frame's triangles (it reads the
// scene); one thread of the recorder's own draws them (OSMesa), compresses
// PNGs and encodes the video meanwhile, overlapping the next steps. Nothing it does changes the
// world: results and the state hash are the same with and without it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "framework/module.h"

namespace swarmsim::video {

struct RecorderSettings {
  std::filesystem::path out_dir;  // the run's output folder: snapshots/ and relative paths
  int64_t snapshot_every = 0;     // steps between snapshots (step 0 too); 0: none
  std::filesystem::path video;    // the MP4 file; empty: no video
  std::string camera;             // a camera or vision sensor's path; empty: the arena view
  int width = 0, height = 0;      // pixels; 0: 640x480 for the arena, a camera's own resolution
  double video_fps = 30;          // frames per simulated second wanted
};

// The frames a video at `fps` frames per simulated second gets with a time
// step of `time_step` s: one every round(1 / (fps time_step)) steps, at least 1.
int64_t FramePeriod(double fps, double time_step);

class Recorder final : public Module {
 public:
  // Checks the settings against the world (the camera exists, the size
  // fits) and creates the video file and the snapshots folder. Throws
  // swarmsim::Error naming the `swarmsim run` option at fault.
  Recorder(World* world, const RecorderSettings& settings);
  ~Recorder() override;

  void Start(World* world) override;
  void Record(const World& world, std::vector<MetricSample>* out) override;
  // Finishes the video (the end of the run, also after an error or a stop signal).
  void WriteOutputs(const std::filesystem::path& dir) const override;
  void ListOutputs(std::vector<OutputFile>* out) const override;

  // Waits for the frames in hand, completes the video file; later calls do
  // nothing. Throws swarmsim::Error if a frame or file could not be written.
  void Finish() const;
  // For the progress bar: "video 120 frames, 12 snapshots".
  std::string ProgressNote() const;
  // What the settings became where they could not be met exactly (the frame
  // rate the time step allows, a size rounded to even), one line each.
  const std::vector<std::string>& notes() const;
  // One line about the video when done: "out/video.mp4: 601 frames, 640x480, 10 frames/s".
  std::string VideoLine() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

ModuleDescriptor RecorderModule();

// Paths of the scene's cameras and vision sensors, in slot order.
std::vector<std::string> CameraPaths(const Scene& scene);

}  // namespace swarmsim::video
