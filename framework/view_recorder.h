// Snapshots and videos of a run's view (`swarmsim run --snapshot-every,
// --video`): the settings the command line gives and what it asks of the
// module that records them, declared here so that the program names no
// rendering code. modules/rendering/video registers the one implementation
// (ModuleRegistry::RegisterViewRecorder); a build without one says so.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace swarmsim {

class World;

struct ViewRecorderSettings {
  std::filesystem::path out_dir;  // the run's output folder: snapshots/ and relative paths
  int64_t snapshot_every = 0;     // steps between snapshots (step 0 too); 0: none
  std::filesystem::path video;    // the MP4 file; empty: no video
  std::string camera;             // a camera or vision sensor's path; empty: the arena view
  int width = 0, height = 0;      // pixels; 0: 640x480 for the arena, a camera's own resolution
  double video_fps = 30;          // frames per simulated second wanted
  // Draw the objects whose visual is a ray (proximity sensors), as the
  // viewer does with its rays switch (framework/visual.h); --no-rays: not.
  bool rays = true;
};

// What the program asks of the recorder it added to a world.
class ViewRecorder {
 public:
  virtual ~ViewRecorder() = default;
  // Waits for the frames in hand, completes the video file; later calls do
  // nothing. Throws swarmsim::Error if a frame or file could not be written.
  virtual void Finish() const = 0;
  // For the progress bar: "video 120 frames, 12 snapshots".
  virtual std::string ProgressNote() const = 0;
  // What the settings became where they could not be met exactly (the frame
  // rate the time step allows, a size rounded to even), one line each.
  virtual const std::vector<std::string>& notes() const = 0;
  // One line about the video when done: "out/video.mp4: 601 frames, 640x480, 10 frames/s".
  virtual std::string VideoLine() const = 0;
};

struct ViewRecorderDescriptor {
  // Adds the recorder to `world` (a record-phase module the world owns) and
  // returns it. Checks the settings against the world (the camera exists,
  // the size fits) and creates the video file and the snapshots folder;
  // throws swarmsim::Error naming the `swarmsim run` option at fault.
  std::function<ViewRecorder*(World* world, const ViewRecorderSettings& settings)> add;
};

}  // namespace swarmsim
