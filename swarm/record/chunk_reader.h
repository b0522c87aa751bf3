// The bounded reading under every recording reader (reader.h; internal to
// swarm/record): a file opened only if it is a regular file (a FIFO or a
// device in place of recording.swrec would block a read forever), read only
// within the bytes it holds, and chunk payloads decompressed only after their
// raw size is checked against the zstd frame header and kMaxChunkRawBytes
// (format.h). No read allocates more than the bytes left in the file, or that
// cap for a decompressed payload. Every error is a swarmsim::Error naming the
// file and a byte offset.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include "framework/regular_file.h"
#include "swarm/record/reader.h"

namespace swarmsim::record {

class RecordingFile {
 public:
  // Opens `path`; throws Error when it is missing, unreadable, or not a
  // regular file (never waits on a FIFO).
  explicit RecordingFile(std::filesystem::path path);
  ~RecordingFile();
  RecordingFile(const RecordingFile&) = delete;
  RecordingFile& operator=(const RecordingFile&) = delete;

  const std::filesystem::path& path() const { return path_; }
  // The size now (a run in progress appends).
  uint64_t CurrentSize() const;
  // The `size` bytes at `offset` into `*bytes`; false, allocating nothing,
  // when the file holds fewer bytes than that from `offset`.
  bool ReadAt(uint64_t offset, uint64_t size, std::string* bytes) const;

 private:
  std::filesystem::path path_;
  std::unique_ptr<RegularFile> file_;
};

// The 24-byte chunk header at `bytes` (FORMAT.md "Chunks"), magic unchecked.
ChunkInfo ParseChunkHeader(const uint8_t* bytes, uint64_t offset);
// "header", "scene", "keyframe", "delta", "end" or "kind 9".
std::string ChunkKindName(uint8_t kind);
// "FILE is corrupt: chunk 3 at byte 612 (scene)" (`index`: from 0; -1: not known).
std::string ChunkPlace(const std::filesystem::path& file, int64_t index, const ChunkInfo& chunk);

// Checks the stored payload's XXH32 against the chunk header's.
void CheckChecksum(std::string_view stored, const ChunkInfo& chunk, const std::string& where);
// Checks that `stored` is exactly one zstd frame whose header gives
// `raw_size` as its content size (if it gives one), and that the size is
// within kMaxChunkRawBytes and what zstd can make of the stored bytes;
// `where` (ChunkPlace) begins the error.
void CheckFrame(std::string_view stored, uint32_t raw_size, const std::string& where);
// CheckFrame, then the payload decompressed (exactly raw_size bytes).
std::string Decompress(std::string_view stored, uint32_t raw_size, const std::string& where);
// Chunk `chunk`'s stored payload, checksum checked, decompressed.
std::string ReadPayload(const RecordingFile& file, const ChunkInfo& chunk,
                        const std::string& where);

}  // namespace swarmsim::record
