// The recorder module ("recorder", record phase, order 300: after paint):
// every N steps it draws a view of the scene (modules/rendering/render.h:
// the arena from above, or a named camera or vision sensor) and writes PNG
// snapshots (DIR/snapshots/step_000120.png) and/or the frames of an H.264
// video (video_writer.h). Made on request: World::AddModule("recorder",
// &settings), or through the registry's view recorder
// (framework/view_recorder.h), as `swarmsim run --snapshot-every/--video`
// does.
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
#include "framework/view_recorder.h"

namespace swarmsim {
class ModuleRegistry;
}

namespace swarmsim::video {

using RecorderSettings = ViewRecorderSettings;

// The frames a video at `fps` frames per simulated second gets with a time
// step of `time_step` s: one every round(1 / (fps time_step)) steps, at least 1.
int64_t FramePeriod(double fps, double time_step);

class Recorder final : public Module, public ViewRecorder {
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

  // ViewRecorder (framework/view_recorder.h).
  void Finish() const override;
  std::string ProgressNote() const override;
  const std::vector<std::string>& notes() const override;
  std::string VideoLine() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

ModuleDescriptor RecorderModule();
// Registers the module and the program's view recorder (its `add`).
void Register(ModuleRegistry* registry);

// Paths of the scene's cameras and vision sensors, in slot order.
std::vector<std::string> CameraPaths(const Scene& scene);

}  // namespace swarmsim::video
