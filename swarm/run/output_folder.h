// The output folder of a run (swarmsim run --out, World.run(out_dir)): made
// and checked before the run, cleared of an earlier run's outputs, and the
// line a failed run's error ends with.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

namespace swarmsim {

// The files a run writes into its folder under fixed names: none of them
// may be a pipe, a device or a folder (CreateOutputFolder), nor the name
// another output (--save-state, --video, view --export) is given.
inline constexpr std::array<const char*, 3> kRunOwnFiles = {"summary.json", "metrics.csv",
                                                            "recording.swrec"};

// The line after a failed run's error: "outputs of the 3 steps that
// finished are in DIR" ("of the 1 step", "(no step finished)"), counting as
// the progress bar does (the error named step 4).
std::string OutputsOfFinishedSteps(int64_t steps, const std::filesystem::path& dir);

// Creates the run's output folder (and its parents). Throws swarmsim::Error
// naming it when it cannot (a file of that name: "'DIR' is not a folder"; a
// loop of links), or when one of kRunOwnFiles there is no ordinary file (a
// pipe named summary.json hung the run).
void CreateOutputFolder(const std::filesystem::path& dir);

// A run with --out DIR where an earlier run wrote: removes the files that
// run's summary.json lists as its outputs (snapshots, video, recording,
// graphs; paths inside DIR only) and the folders they leave empty, so that
// DIR holds one run, not a mix; for a run killed before its end (summary
// status "running", nothing listed), the files under a run's own names
// (recording.swrec, video.mp4, snapshots/, graphs/). Returns the note to
// print ("" if there was nothing), naming what went. `metrics_too`: its
// metrics.csv as well (a run that fails before it writes its own: the
// note named the snapshots it removed, not the metrics with them).
std::string RemoveEarlierOutputs(const std::filesystem::path& dir, bool metrics_too = false);

}  // namespace swarmsim
