#include "swarm/record/chunk_reader.h"

#include <xxhash.h>
#include <zstd.h>

#include <cerrno>
#include <cstring>
#include <new>
#include <sstream>

#include "framework/error.h"
#include "swarm/record/format.h"

namespace swarmsim::record {
namespace {

namespace fs = std::filesystem;

// No zstd frame decompresses to more than this many times its size.
constexpr uint64_t kMaxZstdRatio = 32768;

uint32_t Get32(const uint8_t* p) {
  return p[0] | (uint32_t{p[1]} << 8) | (uint32_t{p[2]} << 16) | (uint32_t{p[3]} << 24);
}

}  // namespace

RecordingFile::RecordingFile(fs::path path) : path_(std::move(path)) {
  std::string why;
  file_ = RegularFile::Open(path_, &why);
  if (file_) return;
  if (std::filesystem::exists(path_) && !std::filesystem::is_regular_file(path_))
    throw Error(path_.string() + " is " + why +
                ", not a recording file: swarmsim reads recordings from regular files only");
  throw Error("cannot read " + path_.string() + ": " + why);
}

RecordingFile::~RecordingFile() = default;

uint64_t RecordingFile::CurrentSize() const {
  const int64_t size = file_->CurrentSize();
  if (size < 0) throw Error("cannot read " + path_.string() + ": " + std::strerror(errno));
  return static_cast<uint64_t>(size);
}

bool RecordingFile::ReadAt(uint64_t offset, uint64_t size, std::string* bytes) const {
  // Never more room than the file has bytes from `offset` on.
  const uint64_t file_size = CurrentSize();
  if (offset > file_size || file_size - offset < size) return false;
  try {
    bytes->resize(size);
  } catch (const std::bad_alloc&) {
    throw Error("cannot read " + path_.string() + ": not enough memory for the " +
                std::to_string(size) + " bytes at byte " + std::to_string(offset));
  }
  std::string why;
  if (file_->ReadAt(offset, bytes->data(), size, &why)) return true;
  if (!why.empty())
    throw Error("cannot read " + path_.string() + " at byte " + std::to_string(offset) + ": " +
                why);
  return false;  // cut shorter since its size was read
}

ChunkInfo ParseChunkHeader(const uint8_t* h, uint64_t offset) {
  ChunkInfo c;
  c.offset = offset;
  c.kind = h[4];
  c.step = Get32(h + 8);
  c.stored_size = Get32(h + 12);
  c.raw_size = Get32(h + 16);
  c.checksum = Get32(h + 20);
  return c;
}

std::string ChunkKindName(uint8_t kind) {
  switch (static_cast<ChunkKind>(kind)) {
    case ChunkKind::kHeader: return "header";
    case ChunkKind::kScene: return "scene";
    case ChunkKind::kKeyframe: return "keyframe";
    case ChunkKind::kDelta: return "delta";
    case ChunkKind::kEnd: return "end";
    case ChunkKind::kLinks: return "links";
  }
  return "kind " + std::to_string(kind);
}

std::string ChunkPlace(const fs::path& file, int64_t index, const ChunkInfo& chunk) {
  return file.string() + " is corrupt: chunk " +
         (index >= 0 ? std::to_string(index + 1) + " " : std::string()) + "at byte " +
         std::to_string(chunk.offset) + " (" + ChunkKindName(chunk.kind) + ")";
}

void CheckChecksum(std::string_view stored, const ChunkInfo& chunk, const std::string& where) {
  const uint32_t sum = XXH32(stored.data(), stored.size(), 0);
  if (sum == chunk.checksum) return;
  std::ostringstream message;
  message << where << ": checksum mismatch (stored 0x" << std::hex << chunk.checksum
          << ", computed 0x" << sum << ")";
  throw Error(message.str());
}

void CheckFrame(std::string_view stored, uint32_t raw_size, const std::string& where) {
  if (raw_size > kMaxChunkRawBytes)
    throw Error(where + ": its header says the payload decompresses to " +
                std::to_string(raw_size) + " bytes, more than the " +
                std::to_string(kMaxChunkRawBytes >> 20) + " MiB a chunk may hold");
  // A zstd block of 4 bytes (an RLE block) gives at most 128 KiB: no frame
  // expands more than kMaxZstdRatio times.
  if (raw_size / kMaxZstdRatio > stored.size())
    throw Error(where + ": its header says " + std::to_string(stored.size()) +
                " stored bytes decompress to " + std::to_string(raw_size) +
                ", more than zstd can make of them");
  const unsigned long long content = ZSTD_getFrameContentSize(stored.data(), stored.size());
  if (content == ZSTD_CONTENTSIZE_ERROR) throw Error(where + ": its payload is not a zstd frame");
  // swarmsim writes the content size; other writers may not (then zstd
  // checks the size when it decompresses).
  if (content != ZSTD_CONTENTSIZE_UNKNOWN && content != raw_size)
    throw Error(where + ": its payload's zstd frame decompresses to " + std::to_string(content) +
                " bytes, but the chunk header says " + std::to_string(raw_size));
  const size_t frame = ZSTD_findFrameCompressedSize(stored.data(), stored.size());
  if (ZSTD_isError(frame))
    throw Error(where + ": its payload's zstd frame is damaged (" + ZSTD_getErrorName(frame) + ")");
  if (frame != stored.size())
    throw Error(where + ": its payload's zstd frame ends after " + std::to_string(frame) +
                " of its " + std::to_string(stored.size()) + " bytes");
}

std::string Decompress(std::string_view stored, uint32_t raw_size, const std::string& where) {
  CheckFrame(stored, raw_size, where);
  std::string raw;
  try {
    raw.resize(raw_size);
  } catch (const std::bad_alloc&) {
    throw Error(where + ": not enough memory to decompress its " + std::to_string(raw_size) +
                " bytes");
  }
  const size_t n = ZSTD_decompress(raw.data(), raw.size(), stored.data(), stored.size());
  if (ZSTD_isError(n))
    throw Error(where + ": its payload does not decompress (" + ZSTD_getErrorName(n) + ")");
  if (n != raw_size)
    throw Error(where + ": its payload decompresses to " + std::to_string(n) + " bytes, not " +
                std::to_string(raw_size));
  return raw;
}

std::string ReadPayload(const RecordingFile& file, const ChunkInfo& chunk,
                        const std::string& where) {
  std::string stored;
  if (!file.ReadAt(chunk.offset + kChunkHeaderSize, chunk.stored_size, &stored))
    throw Error(where + ": the file ends inside its " + std::to_string(chunk.stored_size) +
                "-byte payload (it was cut since it was scanned)");
  CheckChecksum(stored, chunk, where);
  return Decompress(stored, chunk.raw_size, where);
}

}  // namespace swarmsim::record
