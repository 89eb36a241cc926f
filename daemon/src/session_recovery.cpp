// Rebuilding an interrupted session from its journal (session_recovery.hpp).
#include "adit/daemon/session_recovery.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <map>
#include <span>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/common/log.hpp"
#include "adit/daemon/durable_file.hpp"
#include "adit/daemon/map_files.hpp"
#include "adit/daemon/session_frame.hpp"
#include "adit/daemon/tile_spill.hpp"
#include "adit/protocol/session_journal.hpp"
#include "adit/slam/tum.hpp"

namespace adit::daemon {
namespace {

constexpr const char* kJournal = "journal.adj";
constexpr const char* kSummary = "summary.json";
// Left while a recovery runs: found on the next start, it says the recovery
// itself crashed; that session is then marked, not tried again (no crash loop).
constexpr const char* kAttempt = "recovery.attempt";

// A read-only view of a whole file (the journal can exceed RAM).
class MappedFile {
 public:
  explicit MappedFile(const std::filesystem::path& file) {
    fd_ = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) return;
    struct stat st {};
    if (::fstat(fd_, &st) != 0 || st.st_size <= 0) return;
    size_ = static_cast<std::size_t>(st.st_size);
    void* p = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd_, 0);
    if (p != MAP_FAILED) data_ = static_cast<const std::uint8_t*>(p);
  }
  ~MappedFile() {
    if (data_ != nullptr) ::munmap(const_cast<std::uint8_t*>(data_), size_);
    if (fd_ >= 0) ::close(fd_);
  }
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  bool opened() const { return fd_ >= 0; }
  std::span<const std::uint8_t> bytes() const { return data_ ? std::span(data_, size_) : std::span<const std::uint8_t>{}; }

 private:
  int fd_ = -1;
  const std::uint8_t* data_ = nullptr;
  std::size_t size_ = 0;
};

Eigen::Isometry3d isometry_of(const protocol::JournalPose& p) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::Quaterniond(p.orientation[0], p.orientation[1], p.orientation[2], p.orientation[3])
                      .normalized()
                      .toRotationMatrix();
  pose.translation() = Eigen::Vector3d(p.position[0], p.position[1], p.position[2]);
  return pose;
}

// The odometry's trajectory.tum, written live: a torn last line is cut off;
// returns the stamp of its last whole line (nullopt without one).
std::optional<double> last_trajectory_stamp(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  const std::size_t end = text.find_last_of('\n');
  if (end == std::string::npos) return std::nullopt;
  if (end + 1 < text.size()) std::filesystem::resize_file(file, end + 1);
  std::size_t begin = text.find_last_of('\n', end == 0 ? 0 : end - 1);
  begin = begin == std::string::npos || end == 0 ? 0 : begin + 1;
  const std::string line = text.substr(begin, end - begin);
  char* parsed = nullptr;
  const double stamp = std::strtod(line.c_str(), &parsed);
  if (parsed == line.c_str()) return std::nullopt;
  return stamp;
}

nlohmann::json summary_of(const RecoveryReport& r, double voxel_m, double tile_size_m) {
  return {{"session", r.session},
          {"recovered", {{"journal_bytes", r.journal_bytes}, {"cut_bytes", r.cut_bytes}, {"cut_reason", r.cut_reason},
                         {"ended_cleanly", r.ended_cleanly}, {"records", r.records},
                         {"unreadable_records", r.unreadable_records}, {"map_poses", r.map_poses},
                         {"first_stamp_s", r.first_stamp_s}, {"last_stamp_s", r.last_stamp_s}, {"lost_s", r.lost_s},
                         {"problem", r.problem}}},
          {"map", {{"points", r.points}, {"tiles", r.tiles}, {"voxel_m", voxel_m}, {"tile_size_m", tile_size_m},
                   {"keyframes", r.keyframes}}},
          {"frame", frame_summary(r.frame)},
          {"files", r.files}};
}

}  // namespace

std::vector<std::filesystem::path> interrupted_sessions(const std::filesystem::path& sessions_root) {
  std::vector<std::filesystem::path> out;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(sessions_root, ec))
    if (entry.is_directory() && std::filesystem::exists(entry.path() / kJournal) &&
        !std::filesystem::exists(entry.path() / kSummary))
      out.push_back(entry.path());
  std::sort(out.begin(), out.end());
  return out;
}

RecoveryReport recover_session(const std::filesystem::path& dir, const std::vector<std::string>& exports,
                               double tile_size_m) {
  RecoveryReport r;
  r.session = dir.filename().string();
  double voxel_m = 0.0;
  const auto finish = [&] {
    try {
      write_durably(dir / kSummary, summary_of(r, voxel_m, tile_size_m).dump(2) + "\n");
      std::error_code ec;
      std::filesystem::remove(dir / kAttempt, ec);
      if (r.recovered) std::filesystem::remove(dir / kJournal, ec);
    } catch (const std::exception& e) {
      r.recovered = false;
      r.problem = e.what();
    }
    return r;
  };
  if (std::filesystem::exists(dir / kAttempt)) {
    r.problem = "an earlier recovery of this session did not finish: left as it is (its journal is kept)";
    return finish();
  }
  std::ofstream(dir / kAttempt) << "recovering\n";
  try {
    const std::filesystem::path journal_file = dir / kJournal;
    std::map<slam::TileCoord, std::vector<std::span<const std::uint8_t>>> tile_records;
    slam::Trajectory map_poses;
    slam::Trajectory keyframes;
    {
      const MappedFile journal(journal_file);
      if (!journal.opened()) throw std::runtime_error(fmt::format("{}: cannot be read", journal_file.string()));
      const std::span<const std::uint8_t> bytes = journal.bytes();
      r.journal_bytes = bytes.size();
      protocol::JournalReader reader(bytes);
      protocol::JournalPose pose;
      protocol::JournalTilePoints delta;
      while (const std::optional<protocol::JournalReader::Record> rec = reader.next()) {
        ++r.records;
        bool readable = true;
        switch (rec->type) {
          case protocol::JournalRecordType::header: {
            const nlohmann::json h = nlohmann::json::parse(rec->payload.begin(), rec->payload.end(), nullptr, false);
            if (h.is_object()) {
              tile_size_m = h.value("tile_size_m", tile_size_m);
              voxel_m = h.value("voxel_m", voxel_m);
            } else {
              readable = false;
            }
            break;
          }
          case protocol::JournalRecordType::map_pose:
            readable = protocol::decode_journal_pose(rec->payload, pose);
            if (readable) {
              map_poses.stamps.push_back(1e-9 * static_cast<double>(pose.stamp_ns));
              map_poses.poses.push_back(isometry_of(pose));
            }
            break;
          case protocol::JournalRecordType::tile_points:
            // Decoded here to count what is readable (a writer's bug, not a torn
            // tail: the checksum held), and again tile by tile when written.
            readable = protocol::decode_journal_tile_points(rec->payload, delta);
            if (readable) {
              tile_records[{delta.tile[0], delta.tile[1], delta.tile[2]}].push_back(rec->payload);
              r.points += delta.points.size();
            }
            break;
          case protocol::JournalRecordType::keyframe: {
            protocol::JournalKeyframe k;
            readable = protocol::decode_journal_keyframe(rec->payload, k);
            if (readable) {
              keyframes.stamps.push_back(1e-9 * static_cast<double>(k.pose.stamp_ns));
              keyframes.poses.push_back(isometry_of(k.pose));
            }
            break;
          }
          case protocol::JournalRecordType::end:
            r.ended_cleanly = true;
            break;
          default:  // a newer writer's record: not this reader's business
            break;
        }
        if (!readable) ++r.unreadable_records;
      }
      r.cut_reason = reader.stop_reason();
      r.cut_bytes = bytes.size() - reader.good_bytes();
      r.map_poses = map_poses.size();
      r.keyframes = keyframes.size();
      if (!map_poses.stamps.empty()) {
        r.first_stamp_s = map_poses.stamps.front();
        r.last_stamp_s = map_poses.stamps.back();
      }
      if (const std::optional<double> odometry_end = last_trajectory_stamp(dir / "trajectory.tum");
          odometry_end && !map_poses.stamps.empty())
        r.lost_s = std::max(0.0, *odometry_end - r.last_stamp_s);

      // Anchored to a prior map, the exports go into its frame, as at a
      // normal end; levelled when the end had got as far as levelling them.
      const auto read_frame = [&](const char* name, auto read) -> std::optional<Eigen::Isometry3d> {
        try {
          return read(dir / name);
        } catch (const std::exception& e) {
          log::warn("session {}: {}; left out of its exports' frame", r.session, e.what());
          return std::nullopt;
        }
      };
      const std::optional<Eigen::Isometry3d> anchor = read_frame("prior_frame.json", read_prior_frame);
      r.frame = export_frame(anchor, anchor ? std::nullopt : read_frame("level_frame.json", read_level_frame));
      const bool placed = r.frame.source != ExportSource::odometry;
      const Eigen::Isometry3d& placed_by = r.frame.from_odometry;
      // A crash during the session's end may have left the graph's tiles
      // (whole or in part): the recovered map does not follow the graph, so
      // they would not match its map files.
      std::filesystem::remove_all(dir / kGraphTilesFolder);
      std::filesystem::remove_all(dir / kGraphTilesPartialFolder);
      // The tiles and the map files, one tile decoded at a time.
      TileSpill tiles(dir / "tiles", stored_tile_params(tile_size_m));
      std::vector<slam::TileCoord> coords;
      for (const auto& [c, records] : tile_records) coords.push_back(c);
      r.tiles = coords.size();
      std::vector<slam::MapSample> samples;
      const auto read_tile = [&](const slam::TileCoord& c, std::vector<protocol::MapPoint>& points) {
        points.clear();
        for (const std::span<const std::uint8_t> payload : tile_records.at(c))
          if (protocol::decode_journal_tile_points(payload, delta))
            points.insert(points.end(), delta.points.begin(), delta.points.end());
        samples.clear();
        for (const protocol::MapPoint& p : points)
          samples.push_back({Eigen::Vector3f(static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)),
                             p.intensity, p.time});
        if (const std::string problem = tiles.write(c, samples); !problem.empty()) throw std::runtime_error(problem);
        if (placed)  // tiles/ stays in the odometry frame; the map files go into the export frame
          for (protocol::MapPoint& p : points) {
            const Eigen::Vector3d q = placed_by * Eigen::Vector3d(p.x, p.y, p.z);
            p.x = q.x();
            p.y = q.y();
            p.z = q.z();
          }
      };
      r.files = write_map_files(dir, exports, r.points, map_corner(coords, tile_size_m, 0.0, placed_by), coords,
                                read_tile);
      r.files.insert(r.files.begin(), "tiles/");
    }
    if (r.frame.source != ExportSource::odometry) {
      for (slam::Pose& p : map_poses.poses) p = r.frame.from_odometry * p;
      for (slam::Pose& p : keyframes.poses) p = r.frame.from_odometry * p;
      place_trajectory_file(dir / "trajectory.tum", r.frame);
    }
    slam::write_tum(dir / "map_trajectory.tum", map_poses);
    slam::write_tum(dir / "keyframes.tum", keyframes);
    for (const char* f : {"map_trajectory.tum", "keyframes.tum", "trajectory.tum", "config.yaml"}) r.files.push_back(f);
    // The torn tail goes: the next reader (and a next recovery) sees a journal ending on a whole record.
    if (r.cut_bytes > 0) std::filesystem::resize_file(journal_file, r.journal_bytes - r.cut_bytes);
    r.recovered = true;
  } catch (const std::exception& e) {
    r.problem = e.what();
  }
  return finish();
}

std::string describe(const RecoveryReport& r) {
  if (!r.recovered) return fmt::format("session {}: not recovered: {}", r.session, r.problem);
  std::string text = fmt::format(
      "session {}: recovered after a crash: {} map points in {} tiles, {} map poses ({:.1f} s of the session)",
      r.session, r.points, r.tiles, r.map_poses, r.last_stamp_s - r.first_stamp_s);
  if (r.lost_s > 0.0) text += fmt::format("; the map lost the last {:.2f} s the odometry saw", r.lost_s);
  if (r.cut_bytes > 0) text += fmt::format("; {} bytes of torn journal tail cut ({})", r.cut_bytes, r.cut_reason);
  if (r.unreadable_records > 0) text += fmt::format("; {} unreadable records skipped", r.unreadable_records);
  return text;
}

}  // namespace adit::daemon
