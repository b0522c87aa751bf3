// A recording (swarm/record/FORMAT.md) through the reader, as `swarmsim
// record-info DIR` reads it (RecordingPlayer: scan, then every step record
// decoded) and as `swarmsim view DIR --export FILE` does (ScanRecording,
// then ExportFolder of its whole chunks).
#include "framework/error.h"
#include "swarm/record/reader.h"
#include "swarm/viewer/page.h"
#include "tools/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace swarmsim;
  static const std::filesystem::path folder = [] {
    const std::filesystem::path dir = fuzz::TempFolder() / "run";
    std::filesystem::create_directories(dir);
    return dir;
  }();
  fuzz::WriteFile(folder / viewer::kRecordingFile, data, size);
  // record-info.
  try {
    record::RecordingPlayer player(folder);
    while (player.Next()) {
    }
  } catch (const Error& e) {
    fuzz::Rejected(e.what());
  }
  // view --export.
  try {
    const record::RecordingInfo info = record::ScanRecording(folder);
    viewer::ExportFolder(folder, info.valid_size, fuzz::TempFolder() / "export.html");
  } catch (const Error& e) {
    fuzz::Rejected(e.what());
  }
  return 0;
}
