// The recording format's constants (FORMAT.md beside this file): a file of
// chunks, each a 24-byte header and a zstd-compressed payload.
#pragma once

#include <cstdint>

namespace swarmsim::record {

inline constexpr const char* kRecordingFileName = "recording.swrec";
inline constexpr const char* kFormatName = "swarmsim-recording";
inline constexpr int kVersionMajor = 1;
inline constexpr int kVersionMinor =
    2;  // 1.1: objects as their types declare their visuals; 1.2: links

inline constexpr uint8_t kMagic[4] = {'S', 'W', 'R', 'C'};
inline constexpr uint32_t kChunkHeaderSize = 24;

enum class ChunkKind : uint8_t {
  kHeader = 1,
  kScene = 2,
  kKeyframe = 3,
  kDelta = 4,
  kEnd = 5,
  kLinks = 6,  // 1.2: who was linked to whom at the step record before it
};

// Quantisation of the step records' poses.
inline constexpr double kPositionUnit = 1e-4;      // m per position integer
inline constexpr double kQuaternionScale = 32767;  // integer per quaternion unit
// A proximity reading: 65535 nothing detected, else distance / range * 65534.
inline constexpr uint16_t kNoDetection = 65535;

// What a reader accepts (FORMAT.md "Limits"): beyond these a file is refused
// as corrupt instead of allocated.
inline constexpr uint32_t kMaxChunkRawBytes = uint32_t{256} << 20;  // a payload, decompressed
inline constexpr uint64_t kMaxPaintCells = uint64_t{1} << 26;       // paint width x height
inline constexpr int kMaxJsonDepth = 64;                            // nesting in a JSON chunk
// Bytes of one object's pose in a step record (u32 id, 3 x i32, 4 x i16): a
// keyframe lists every object of its scene, so it holds at least this times
// the scene's object count.
inline constexpr uint32_t kPoseBytes = 24;

}  // namespace swarmsim::record
