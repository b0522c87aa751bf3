// The recording format's constants (FORMAT.md beside this file): a file of
// chunks, each a 24-byte header and a zstd-compressed payload.
#pragma once

#include <cstdint>

namespace swarmsim::record {

inline constexpr const char* kRecordingFileName = "recording.swrec";
inline constexpr const char* kFormatName = "swarmsim-recording";
inline constexpr int kVersionMajor = 1;
inline constexpr int kVersionMinor = 0;

inline constexpr uint8_t kMagic[4] = {'S', 'W', 'R', 'C'};
inline constexpr uint32_t kChunkHeaderSize = 24;

enum class ChunkKind : uint8_t { kHeader = 1, kScene = 2, kKeyframe = 3, kDelta = 4, kEnd = 5 };

// Quantisation of the step records' poses.
inline constexpr double kPositionUnit = 1e-4;      // m per position integer
inline constexpr double kQuaternionScale = 32767;  // integer per quaternion unit
// A proximity reading: 65535 nothing detected, else distance / range * 65534.
inline constexpr uint16_t kNoDetection = 65535;

}  // namespace swarmsim::record
