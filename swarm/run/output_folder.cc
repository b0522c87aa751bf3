// The run's output folder (output_folder.h).
#include "swarm/run/output_folder.h"

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <system_error>

#include "framework/error.h"
#include "framework/regular_file.h"

namespace swarmsim {

void CreateOutputFolder(const std::filesystem::path& dir) {
  std::error_code ec;
  (void)std::filesystem::status(dir, ec);
  if (ec == std::make_error_condition(std::errc::too_many_symbolic_link_levels))
    throw Error("'" + dir.string() + "' is a loop of symbolic links; pass a folder");
  if (std::filesystem::is_symlink(dir, ec) && !std::filesystem::exists(dir, ec))
    throw Error("'" + dir.string() + "' is a symbolic link to '" +
                std::filesystem::read_symlink(dir, ec).string() +
                "', which does not exist; make that folder, or pass another");
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec))
    throw Error("'" + dir.string() + "' is not a folder; pass a folder (it is made if missing)");
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error("cannot create output folder '" + dir.string() + "': " + ec.message());
  // The run's own files there: a pipe named summary.json hung the run (its
  // writer waits for a reader), a folder threw a stream's error naming none.
  for (const char* own : kRunOwnFiles)
    if (const std::string why = NotAnOrdinaryFile(dir / own); !why.empty())
      throw Error("'" + (dir / own).string() + "': " + why + ", and the run writes its " + own +
                  " there; remove it or pass another folder");
}

std::string OutputsOfFinishedSteps(int64_t steps, const std::filesystem::path& dir) {
  const std::string which = steps == 0 ? " (no step finished)"
                            : steps == 1
                                ? " of the 1 step that finished"
                                : " of the " + std::to_string(steps) + " steps that finished";
  return "outputs" + which + " are in " + dir.string();
}

namespace {

// The earlier run's files that its summary.json lists (or, for a run that
// never ended, those under the names a run gives them), removed: "1
// recording, 3 snapshots", or "".
std::string RemoveListedOutputs(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::is_regular_file(dir / "summary.json", error)) return "";  // a pipe's read would wait
  std::ifstream in(dir / "summary.json");
  if (!in) return "";
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object() || !j.contains("outputs") || !j["outputs"].is_array()) return "";
  std::map<std::string, int> removed;  // kind -> files
  std::set<fs::path> folders;
  nlohmann::json outputs = j["outputs"];
  // A run that never ended (killed: its summary still says running) listed
  // nothing: its files under the names a run gives them go instead.
  if (j.contains("status") && j["status"] == "running") {
    std::error_code ec;
    for (const auto& [name, kind] :
         {std::pair{"recording.swrec", "recording"}, std::pair{"video.mp4", "video"}})
      if (fs::is_regular_file(dir / name, ec)) outputs.push_back({{"path", name}, {"kind", kind}});
    for (const char* folder : {"snapshots", "graphs"})
      for (const fs::directory_entry& entry : fs::directory_iterator(dir / folder, ec))
        if (entry.is_regular_file(ec))
          outputs.push_back({{"path", (fs::path(folder) / entry.path().filename()).string()},
                             {"kind", folder == std::string("snapshots") ? "snapshot" : "graph"}});
  }
  for (const nlohmann::json& file : outputs) {
    if (!file.is_object() || !file.contains("path") || !file["path"].is_string()) continue;
    const fs::path path = fs::path(file["path"].get<std::string>()).lexically_normal();
    // Only what the earlier run wrote inside DIR.
    if (path.empty() || path.is_absolute() || *path.begin() == "..") continue;
    std::error_code ec;
    if (!fs::is_regular_file(dir / path, ec) || !fs::remove(dir / path, ec)) continue;
    ++removed[file.contains("kind") && file["kind"].is_string() ? file["kind"].get<std::string>()
                                                                : "file"];
    for (fs::path up = path.parent_path(); !up.empty(); up = up.parent_path()) folders.insert(up);
  }
  // Deepest first: a folder emptied by the files above (not one holding others).
  for (auto it = folders.rbegin(); it != folders.rend(); ++it) {
    std::error_code ec;
    if (fs::is_empty(dir / *it, ec)) fs::remove(dir / *it, ec);
  }
  std::string what;
  for (const auto& [kind, count] : removed)
    what +=
        (what.empty() ? "" : ", ") + std::to_string(count) + " " + kind + (count == 1 ? "" : "s");
  return what;
}

std::string Removed(const std::filesystem::path& dir, const std::string& what) {
  return "removed the outputs of the earlier run in '" + dir.string() + "' (" + what +
         "), so that the folder holds this run's alone";
}

}  // namespace

std::string RemoveEarlierOutputs(const std::filesystem::path& dir, bool metrics_too) {
  namespace fs = std::filesystem;
  std::error_code error;
  // metrics.csv, which a run that runs writes anew: named in the note.
  const bool metrics = metrics_too && fs::is_regular_file(dir / "metrics.csv", error) &&
                       fs::remove(dir / "metrics.csv", error);
  const std::string others = RemoveListedOutputs(dir);
  if (!metrics) return others.empty() ? "" : Removed(dir, others);
  return Removed(dir, others.empty() ? "metrics.csv" : "metrics.csv, " + others);
}

}  // namespace swarmsim
