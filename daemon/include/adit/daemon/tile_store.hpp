#pragma once
// The encoded map tiles of one session, each with a version that increases
// whenever the tile changes, cut into segments (protocol/tile_codec.hpp) that
// each remember the version at which they last changed. Owned by the
// publisher thread.
//
// Where the segments' bytes lie. A session's tiles grow all session (82 MB of
// frames at the end of a 30-minute drive), so with a spool folder the store
// keeps in RAM only an index (version, hash, point count, file offset: ~50
// bytes per segment of 1024 points) and the frame of each tile's last,
// partial segment, which changes at almost every update:
// - a full segment's frame is appended to an unnamed file in the spool folder
//   (the session's folder) and read back (pread) when it is sent. Full
//   segments change only when the mapper reorders a tile (a tile read back
//   from tiles/ comes sorted per stored segment), so the file holds little
//   besides live frames; it is unlinked at once and vanishes with the store.
// - a stored session's tiles (insert_file) stay in their tiles/<id>.adt files,
//   read by offset.
// Without a spool folder (tests, or when the file cannot be made) every frame
// stays in RAM, as it did before. I/O failures are returned naming the file.

#include <cstdint>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "adit/protocol/map_point.hpp"
#include "adit/protocol/tile_codec.hpp"

namespace adit::daemon {

// Where a segment's frame is when it is not in TileSegment::frame.
struct FrameLocation {
  static constexpr std::uint32_t kInMemory = 0xFFFFFFFFU;
  std::uint32_t file = kInMemory;  // index of the store's file (0: the spool)
  std::uint32_t bytes = 0;
  std::uint64_t offset = 0;
};

struct EncodedTile {
  std::int64_t id = 0;
  std::int32_t version = 0;  // 1 for the first content
  std::int64_t utime = 0;    // when this version was made
  std::int32_t n_points = 0;
  protocol::TileParams params;  // tile size and quantum of its segments
  // Version, hash and point count of each segment; `frame` is empty for a
  // segment whose bytes are in a file (`where`).
  std::vector<protocol::TileSegment> segments;
  std::vector<FrameLocation> where;  // one per segment
  std::int32_t n_segments() const { return static_cast<std::int32_t>(segments.size()); }
  // The size of segment s's frame, wherever it is.
  std::size_t frame_bytes(std::size_t s) const {
    return where[s].file == FrameLocation::kInMemory ? segments[s].frame.size() : where[s].bytes;
  }
};

// An open file, closed when dropped.
class FileHandle {
 public:
  FileHandle() = default;
  explicit FileHandle(int fd) : fd_(fd) {}
  FileHandle(FileHandle&& other) noexcept : fd_(other.release()) {}
  FileHandle& operator=(FileHandle&& other) noexcept;
  FileHandle(const FileHandle&) = delete;
  FileHandle& operator=(const FileHandle&) = delete;
  ~FileHandle();
  int get() const { return fd_; }
  explicit operator bool() const { return fd_ >= 0; }
  int release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }

 private:
  int fd_ = -1;
};

class TileStore {
 public:
  // Every frame in RAM.
  explicit TileStore(protocol::TileParams params) : params_(params) {}
  // Full segments' frames in an unnamed file in `spool_dir`. When it cannot
  // be made, frames stay in RAM and spool_problem() says why. The file is
  // rewritten with only its live frames when it exceeds twice them plus
  // `spool_slack_bytes`.
  TileStore(protocol::TileParams params, const std::filesystem::path& spool_dir,
            std::uint64_t spool_slack_bytes = std::uint64_t{32} << 20);

  // The new whole content of tile `key` (append order): only the segments
  // that changed are re-encoded. The version goes up by one when anything
  // changed; returns false (and keeps the version) when nothing did.
  bool update(protocol::TileKey key, std::span<const protocol::MapPoint> points, std::int64_t utime);
  // The same when the tile's first `first_point` points are those of its
  // last update and `tail` follows them: costs the tail, not the tile
  // (protocol::append_segments). Returns "" (with `changed`), or why not,
  // naming the tile; then the tile is as it was.
  std::string append(protocol::TileKey key, std::size_t first_point, std::span<const protocol::MapPoint> tail,
                     std::int64_t utime, bool& changed);
  // Adds a tile encoded earlier (a stored session's tiles/<id>.adt, format 1
  // or 2), as version 1. Returns "", or why the blob is not a usable tile
  // (then nothing is added).
  std::string insert_encoded(std::int64_t id, std::span<const std::uint8_t> blob, std::int64_t utime);
  // The same from the file itself: checked whole, then (format 2) only its
  // segment table stays in RAM and frames are read from the file when sent.
  // Returns "" or why not, naming the file.
  std::string insert_file(std::int64_t id, const std::filesystem::path& file, std::int64_t utime);
  // Segment s's frame into `out` (replaced): "" or why it cannot be read, naming the file.
  std::string read_frame(const EncodedTile& tile, std::size_t s, std::vector<std::uint8_t>& out) const;

  const EncodedTile* find(std::int64_t id) const;
  const std::map<std::int64_t, EncodedTile>& tiles() const { return tiles_; }
  const protocol::TileParams& params() const { return params_; }
  std::int64_t total_points() const { return total_points_; }

  // Frame bytes held in RAM (what grows with the session without a spool).
  std::uint64_t frame_bytes_in_ram() const { return frame_bytes_in_ram_; }
  // The spool file's size (live frames and those replaced since), its live
  // frames, and how many times it was rewritten with only those.
  std::uint64_t spool_bytes() const { return spool_bytes_; }
  std::uint64_t spool_live_bytes() const { return spool_live_bytes_; }
  std::uint64_t spool_compactions() const { return spool_compactions_; }
  bool spooling() const { return static_cast<bool>(spool_); }
  // Why there is no spool although a folder was given ("" otherwise).
  const std::string& spool_problem() const { return spool_problem_; }
  // Frames that could not be written to the spool (kept in RAM) and the first reason.
  std::uint64_t spool_write_errors() const { return spool_write_errors_; }
  const std::string& first_write_problem() const { return first_write_problem_; }

 private:
  // Moves the frames of full segments [first, n) of `tile` to the spool.
  // (Full: tile.params.segment_points.)
  // The bookkeeping once `tile`'s segments hold new content from segment
  // `first` on: whether anything changed (then its version goes up).
  bool changed(EncodedTile& tile, std::size_t first, std::uint64_t ram_before, std::size_t n_points,
               std::int64_t utime);
  void spill_frames(EncodedTile& tile, std::size_t first);
  std::string insert_blob(std::int64_t id, std::span<const std::uint8_t> blob, std::int64_t utime, bool spill);
  FileHandle open_spool(const std::filesystem::path& dir, std::string& problem);
  static bool write_all(int fd, std::span<const std::uint8_t> bytes, std::uint64_t offset);
  void compact_spool();

  protocol::TileParams params_;
  std::map<std::int64_t, EncodedTile> tiles_;
  std::int64_t total_points_ = 0;
  std::uint64_t frame_bytes_in_ram_ = 0;
  // files_[0] is the spool ("" when none); others are stored tiles' files.
  std::vector<std::filesystem::path> files_{std::filesystem::path{}};
  FileHandle spool_;
  std::filesystem::path spool_dir_;
  std::uint64_t spool_slack_bytes_ = 0;
  std::uint64_t spool_bytes_ = 0;
  std::uint64_t spool_live_bytes_ = 0;
  std::uint64_t spool_compactions_ = 0;
  std::string spool_problem_;
  std::uint64_t spool_write_errors_ = 0;
  std::string first_write_problem_;
  // The last stored file opened: segments are mostly sent tile by tile.
  mutable std::uint32_t open_file_ = FrameLocation::kInMemory;
  mutable FileHandle open_handle_;
};

}  // namespace adit::daemon
