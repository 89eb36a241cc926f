#pragma once
// The session journal's writer (protocol/session_journal.hpp; docs/SESSIONS.md):
// the mapping thread hands it each mapped scan's pose, the points each tile
// confirmed and each keyframe; a thread of its own ("journal", nice, not
// watched: a slow card must not get aditd restarted) compresses and appends
// them to <session>/journal.adj and makes them durable with fdatasync at
// most every `sync_period_s`. So a crash loses what the mapping thread had
// not handed over yet plus at most one sync period (a killed process loses
// nothing written; a pulled battery can lose the period's page cache).
//
// The queue is unbounded and under a mutex (the mapping thread, not the
// odometry, is its producer, and nothing may be dropped). A write error
// (disk full) stops the journal for the rest of the session: counted, named
// in fault(), the mapping goes on; what was written stays whole.

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "adit/daemon/stage_thread.hpp"
#include "adit/protocol/session_journal.hpp"
#include "adit/slam/tiled_map.hpp"

namespace adit::daemon {

struct JournalStats {
  std::atomic<std::uint64_t> records{0};
  std::atomic<std::uint64_t> bytes{0};
  std::atomic<std::uint64_t> syncs{0};
  std::atomic<std::uint64_t> lost_records{0};  // handed over after a write error
  std::atomic<std::uint64_t> queued{0};         // waiting to be written now
};

class JournalWriter {
 public:
  // `stop`: the pipeline's stop flag (the thread drains and ends on close() regardless).
  JournalWriter(std::filesystem::path file, double sync_period_s, const std::atomic<bool>& stop);
  ~JournalWriter();
  JournalWriter(const JournalWriter&) = delete;
  JournalWriter& operator=(const JournalWriter&) = delete;

  // Creates the file (throws adit::InputError naming it), writes the header
  // record (`header_json`) and starts the thread.
  void start(const std::string& header_json);
  // From the mapping thread: copies what it is given and returns.
  void map_pose(std::int64_t stamp_ns, const Eigen::Isometry3d& pose);
  void tile_points(const slam::TileCoord& tile, std::span<const slam::MapSample> points);
  void keyframe(std::int64_t stamp_ns, const Eigen::Isometry3d& pose, std::span<const Eigen::Vector3f> points);
  // Writes what is queued, an end record when `clean`, syncs, joins. Idempotent.
  void close(bool clean);

  const JournalStats& stats() const { return stats_; }
  std::string fault() const;  // "" or the write error that stopped the journal
  StageThread& thread() { return thread_; }
  const std::filesystem::path& file() const { return file_; }

 private:
  // One record's data as handed over; encoded on the journal thread.
  struct Entry {
    protocol::JournalRecordType type = protocol::JournalRecordType::map_pose;
    protocol::JournalPose pose;
    protocol::JournalTilePoints tile;                 // tile_points
    std::vector<std::array<float, 3>> body_points;    // keyframe
  };
  void push(Entry&& entry);
  void loop();
  void write_batch(std::vector<Entry>& batch);
  void write_bytes(std::span<const std::uint8_t> bytes);
  void sync();

  const std::filesystem::path file_;
  const double sync_period_s_;
  StageThread thread_;
  int fd_ = -1;  // closed by close()
  std::mutex mutex_;  // the queue and closing_
  std::condition_variable ready_;
  std::vector<Entry> queue_;
  bool closing_ = false;
  bool clean_ = false;
  bool closed_ = false;
  // Journal thread only.
  std::vector<std::uint8_t> buffer_;
  std::vector<std::uint8_t> payload_;
  bool dirty_ = false;
  std::int64_t last_sync_ns_ = 0;
  mutable std::mutex fault_mutex_;
  std::string fault_;
  std::atomic<bool> failed_{false};
  JournalStats stats_;
};

}  // namespace adit::daemon
