#include "adit/daemon/tile_store.hpp"

#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <system_error>

#include <fmt/format.h>

namespace adit::daemon {
namespace {

std::string errno_text() { return std::error_code(errno, std::generic_category()).message(); }

std::uint64_t ram_frame_bytes(const EncodedTile& tile) {
  std::uint64_t bytes = 0;
  for (std::size_t s = 0; s < tile.segments.size(); ++s)
    if (s >= tile.where.size() || tile.where[s].file == FrameLocation::kInMemory) bytes += tile.segments[s].frame.size();
  return bytes;
}

}  // namespace

FileHandle& FileHandle::operator=(FileHandle&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.release();
  }
  return *this;
}

FileHandle::~FileHandle() {
  if (fd_ >= 0) ::close(fd_);
}

// mkstemp then unlink: the file has no name, so nothing is left behind when
// the daemon stops or crashes, and its blocks are freed with the store.
FileHandle TileStore::open_spool(const std::filesystem::path& dir, std::string& problem) {
  std::string name = (dir / ".tile-stream-XXXXXX").string();
  const int fd = ::mkostemp(name.data(), O_CLOEXEC);
  if (fd < 0) {
    problem = fmt::format("{}: cannot create the tile stream's segment file: {}", name, errno_text());
    return {};
  }
  ::unlink(name.c_str());
  files_[0] = name;
  return FileHandle(fd);
}

TileStore::TileStore(protocol::TileParams params, const std::filesystem::path& spool_dir,
                     std::uint64_t spool_slack_bytes)
    : params_(params), spool_dir_(spool_dir), spool_slack_bytes_(spool_slack_bytes) {
  spool_ = open_spool(spool_dir, spool_problem_);
}

bool TileStore::write_all(int fd, std::span<const std::uint8_t> bytes, std::uint64_t offset) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pwrite(fd, bytes.data() + done, bytes.size() - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

// Frames replaced since they were appended stay in the file as garbage (a
// tile read back from tiles/ comes reordered, so its full segments change);
// once garbage exceeds the live frames and the slack, the live ones are
// copied to a new file, so the file stays below twice the live frames plus
// the slack. On any failure the old file stays in use.
void TileStore::compact_spool() {
  if (!spool_ || spool_bytes_ <= 2 * spool_live_bytes_ + spool_slack_bytes_) return;
  std::string problem;
  const std::filesystem::path old_name = files_[0];
  FileHandle fresh = open_spool(spool_dir_, problem);
  if (!fresh) {
    files_[0] = old_name;
    if (spool_write_errors_++ == 0) first_write_problem_ = problem;
    spool_slack_bytes_ = spool_bytes_;  // do not retry at every update
    return;
  }
  const std::filesystem::path new_name = files_[0];
  files_[0] = old_name;  // read_frame reads the old file meanwhile
  std::uint64_t at = 0;
  std::vector<std::uint8_t> frame;
  std::vector<std::pair<FrameLocation*, std::uint64_t>> moved;
  for (auto& [id, tile] : tiles_) {
    for (std::size_t s = 0; s < tile.where.size(); ++s) {
      if (tile.where[s].file != 0) continue;
      if (!read_frame(tile, s, frame).empty() || !write_all(fresh.get(), frame, at)) {
        if (spool_write_errors_++ == 0)
          first_write_problem_ = fmt::format("{}: cannot compact the tile stream's segment file", new_name.string());
        spool_slack_bytes_ = spool_bytes_;
        return;
      }
      moved.emplace_back(&tile.where[s], at);
      at += frame.size();
    }
  }
  for (auto& [where, offset] : moved) where->offset = offset;
  spool_ = std::move(fresh);
  files_[0] = new_name;
  spool_bytes_ = at;
  spool_live_bytes_ = at;
  ++spool_compactions_;
}

void TileStore::spill_frames(EncodedTile& tile, std::size_t first) {
  if (!spool_) return;
  for (std::size_t s = first; s < tile.segments.size(); ++s) {
    protocol::TileSegment& segment = tile.segments[s];
    // The last, partial segment changes at almost every update: it stays.
    if (segment.n_points < tile.params.segment_points || segment.frame.empty()) continue;
    const std::size_t size = segment.frame.size();
    if (!write_all(spool_.get(), segment.frame, spool_bytes_)) {  // disk full or failing: this frame stays in RAM
      if (spool_write_errors_++ == 0)
        first_write_problem_ = fmt::format("{}: cannot append a tile segment: {}", files_[0].string(), errno_text());
      continue;
    }
    tile.where[s] = {0, static_cast<std::uint32_t>(size), spool_bytes_};
    spool_bytes_ += size;
    spool_live_bytes_ += size;
    std::vector<std::uint8_t>().swap(segment.frame);
  }
}

bool TileStore::update(protocol::TileKey key, std::span<const protocol::MapPoint> points, std::int64_t utime) {
  const std::int64_t id = protocol::tile_id(key);
  EncodedTile& tile = tiles_[id];
  tile.id = id;
  tile.params = params_;
  // Only version, hash and point count of the old segments are compared, so
  // those whose frames are in a file need not be read back.
  const std::uint64_t before = ram_frame_bytes(tile);
  const std::size_t first = protocol::update_segments(key, points, params_, tile.version + 1, tile.segments);
  return changed(tile, first, before, points.size(), utime);
}

std::string TileStore::append(protocol::TileKey key, std::size_t first_point,
                              std::span<const protocol::MapPoint> tail, std::int64_t utime, bool& changed_out) {
  changed_out = false;
  const std::int64_t id = protocol::tile_id(key);
  if (first_point > 0 && !tiles_.contains(id))
    return fmt::format("tile {}: the update starts at point {} of a tile never sent", id, first_point);
  EncodedTile& tile = tiles_[id];
  tile.id = id;
  tile.params = params_;
  const std::uint64_t before = ram_frame_bytes(tile);
  std::size_t first = 0;
  if (std::string problem =
          protocol::append_segments(key, first_point, tail, params_, tile.version + 1, tile.segments, first);
      !problem.empty())
    return fmt::format("tile {}: {}", id, problem);
  changed_out = changed(tile, first, before, first_point + tail.size(), utime);
  return {};
}

// After tile.segments were brought to the new content from segment `first` on.
bool TileStore::changed(EncodedTile& tile, std::size_t first, std::uint64_t ram_before, std::size_t n_points,
                        std::int64_t utime) {
  if (first == tile.segments.size() && tile.where.size() == tile.segments.size()) return false;
  // From `first` on, the old frames are replaced (or gone): garbage in the spool.
  for (std::size_t s = first; s < tile.where.size(); ++s)
    if (tile.where[s].file == 0) spool_live_bytes_ -= tile.where[s].bytes;
  tile.where.resize(tile.segments.size());
  for (std::size_t s = first; s < tile.where.size(); ++s) tile.where[s] = {};  // the new frames are in RAM
  spill_frames(tile, first);
  compact_spool();
  frame_bytes_in_ram_ = frame_bytes_in_ram_ - ram_before + ram_frame_bytes(tile);
  total_points_ += static_cast<std::int64_t>(n_points) - tile.n_points;
  tile.version += 1;
  tile.utime = utime;
  tile.n_points = static_cast<std::int32_t>(n_points);
  return true;
}

std::string TileStore::insert_encoded(std::int64_t id, std::span<const std::uint8_t> blob, std::int64_t utime) {
  return insert_blob(id, blob, utime, true);
}

std::string TileStore::insert_blob(std::int64_t id, std::span<const std::uint8_t> blob, std::int64_t utime,
                                   bool spill) {
  protocol::TileParams params = params_;
  std::vector<protocol::TileSegment> segments;
  if (std::string problem = protocol::unpack_tile(blob, protocol::tile_key(id), params, segments); !problem.empty())
    return problem;
  std::int64_t n_points = 0;
  for (const protocol::TileSegment& s : segments) n_points += s.n_points;
  EncodedTile& tile = tiles_[id];
  frame_bytes_in_ram_ -= ram_frame_bytes(tile);
  for (const FrameLocation& where : tile.where)
    if (where.file == 0) spool_live_bytes_ -= where.bytes;
  total_points_ += n_points - tile.n_points;
  tile.id = id;
  tile.version = 1;
  tile.utime = utime;
  tile.n_points = static_cast<std::int32_t>(n_points);
  tile.params = params;  // a stored tile's segments may be larger than the stream's
  tile.segments = std::move(segments);
  tile.where.assign(tile.segments.size(), FrameLocation{});
  if (spill) spill_frames(tile, 0);
  frame_bytes_in_ram_ += ram_frame_bytes(tile);
  return {};
}

std::string TileStore::insert_file(std::int64_t id, const std::filesystem::path& file, std::int64_t utime) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return fmt::format("{}: cannot open the tile", file.string());
  const std::vector<std::uint8_t> blob((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return fmt::format("{}: cannot read the tile", file.string());
  // The whole file is checked as before (every frame's size against its
  // point count), one tile at a time.
  // Formats 2 and 3 (segments; 3 with the origin centred) index alike.
  const bool segmented = blob.size() >= protocol::kTileHeaderBytesFormat2 && (blob[4] == 2 || blob[4] == 3) && blob[5] == 0;
  // A format-1 tile is re-cut into new frames: those go to the spool, if any.
  if (std::string problem = insert_blob(id, blob, utime, !segmented); !problem.empty())
    return fmt::format("{}: {}", file.string(), problem);
  if (!segmented) return {};
  EncodedTile& tile = tiles_.at(id);
  // Formats 2 and 3: the frames lie at known offsets of the file; only those stay.
  const auto index = static_cast<std::uint32_t>(files_.size());
  files_.push_back(file);
  std::uint64_t at = protocol::kTileHeaderBytesFormat2 + 4 * tile.segments.size();
  frame_bytes_in_ram_ -= ram_frame_bytes(tile);
  for (std::size_t s = 0; s < tile.segments.size(); ++s) {
    // unpack_tile copied each frame verbatim, in file order.
    const auto size = static_cast<std::uint32_t>(tile.segments[s].frame.size());
    tile.where[s] = {index, size, at};
    at += size;
    std::vector<std::uint8_t>().swap(tile.segments[s].frame);
  }
  return {};
}

std::string TileStore::read_frame(const EncodedTile& tile, std::size_t s, std::vector<std::uint8_t>& out) const {
  out.clear();
  if (s >= tile.segments.size()) return fmt::format("tile {} has no segment {}", tile.id, s);
  const FrameLocation& where = tile.where[s];
  if (where.file == FrameLocation::kInMemory) {
    out = tile.segments[s].frame;
    return {};
  }
  int fd = -1;
  if (where.file == 0) {
    fd = spool_.get();
  } else {
    if (open_file_ != where.file) {
      open_handle_ = FileHandle(::open(files_[where.file].c_str(), O_RDONLY | O_CLOEXEC));
      open_file_ = open_handle_ ? where.file : FrameLocation::kInMemory;
      if (!open_handle_) return fmt::format("{}: cannot open the tile: {}", files_[where.file].string(), errno_text());
    }
    fd = open_handle_.get();
  }
  out.resize(where.bytes);
  std::size_t done = 0;
  while (done < out.size()) {
    const ssize_t n = ::pread(fd, out.data() + done, out.size() - done, static_cast<off_t>(where.offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return fmt::format("{}: cannot read segment {} of tile {}: {}", files_[where.file].string(), s, tile.id,
                                  errno_text());
    if (n == 0) break;
    done += static_cast<std::size_t>(n);
  }
  if (done < out.size()) {
    out.clear();
    return fmt::format("{}: segment {} of tile {} is cut short (file changed since it was indexed?)",
                       files_[where.file].string(), s, tile.id);
  }
  return {};
}

const EncodedTile* TileStore::find(std::int64_t id) const {
  const auto it = tiles_.find(id);
  return it == tiles_.end() ? nullptr : &it->second;
}

}  // namespace adit::daemon
