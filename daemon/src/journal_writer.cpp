// The session journal's writer thread (journal_writer.hpp).
#include "adit/daemon/journal_writer.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "adit/common/clock.hpp"
#include "adit/common/error.hpp"
#include "adit/common/log.hpp"

namespace adit::daemon {
namespace {

protocol::JournalPose journal_pose(std::int64_t stamp_ns, const Eigen::Isometry3d& pose) {
  protocol::JournalPose p;
  p.stamp_ns = stamp_ns;
  const Eigen::Vector3d t = pose.translation();
  const Eigen::Quaterniond q(pose.linear());
  p.position = {t.x(), t.y(), t.z()};
  p.orientation = {q.w(), q.x(), q.y(), q.z()};
  return p;
}

}  // namespace

JournalWriter::JournalWriter(std::filesystem::path file, double sync_period_s, const std::atomic<bool>& stop)
    : file_(std::move(file)), sync_period_s_(sync_period_s), thread_("journal", config::ThreadSettings{}, stop) {}

JournalWriter::~JournalWriter() { close(false); }

void JournalWriter::start(const std::string& header_json) {
  fd_ = ::open(file_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) throw InputError(file_.string(), "", fmt::format("cannot create the session journal: {}", std::strerror(errno)));
  std::vector<std::uint8_t> header(header_json.begin(), header_json.end());
  protocol::append_journal_record(buffer_, protocol::JournalRecordType::header, header);
  write_bytes(buffer_);
  buffer_.clear();
  sync();
  last_sync_ns_ = monotonic_ns();
  thread_.start([this] { loop(); });
}

void JournalWriter::push(Entry&& entry) {
  if (failed_.load(std::memory_order_relaxed)) {
    stats_.lost_records.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  {
    const std::lock_guard lock(mutex_);
    queue_.push_back(std::move(entry));
    stats_.queued.store(queue_.size(), std::memory_order_relaxed);
  }
  ready_.notify_one();
}

void JournalWriter::map_pose(std::int64_t stamp_ns, const Eigen::Isometry3d& pose) {
  Entry e;
  e.type = protocol::JournalRecordType::map_pose;
  e.pose = journal_pose(stamp_ns, pose);
  push(std::move(e));
}

void JournalWriter::tile_points(const slam::TileCoord& tile, std::span<const slam::MapSample> points) {
  Entry e;
  e.type = protocol::JournalRecordType::tile_points;
  e.tile.tile = {tile.x, tile.y, tile.z};
  e.tile.points.reserve(points.size());
  for (const slam::MapSample& s : points)
    e.tile.points.push_back({s.position.x(), s.position.y(), s.position.z(), s.intensity, s.time_s});
  push(std::move(e));
}

void JournalWriter::keyframe(std::int64_t stamp_ns, const Eigen::Isometry3d& pose,
                             std::span<const Eigen::Vector3f> points) {
  Entry e;
  e.type = protocol::JournalRecordType::keyframe;
  e.pose = journal_pose(stamp_ns, pose);
  e.body_points.reserve(points.size());
  for (const Eigen::Vector3f& p : points) e.body_points.push_back({p.x(), p.y(), p.z()});
  push(std::move(e));
}

void JournalWriter::loop() {
  const auto period = std::chrono::duration<double>(sync_period_s_);
  std::vector<Entry> batch;
  while (true) {
    bool closing = false;
    {
      std::unique_lock lock(mutex_);
      ready_.wait_for(lock, period, [&] { return !queue_.empty() || closing_; });
      batch.swap(queue_);
      stats_.queued.store(0, std::memory_order_relaxed);
      closing = closing_;
    }
    thread_.beat.beat();
    write_batch(batch);
    batch.clear();
    if (dirty_ && (closing || monotonic_ns() - last_sync_ns_ >= static_cast<std::int64_t>(sync_period_s_ * 1e9))) sync();
    if (closing) {
      const std::lock_guard lock(mutex_);
      if (queue_.empty()) break;
    }
  }
  if (clean_ && !failed_) {
    buffer_.clear();  // it still holds the last batch, written already
    protocol::append_journal_record(buffer_, protocol::JournalRecordType::end, {});
    write_bytes(buffer_);
    buffer_.clear();
  }
  if (dirty_) sync();
}

void JournalWriter::write_batch(std::vector<Entry>& batch) {
  if (batch.empty()) return;
  if (failed_) {
    stats_.lost_records.fetch_add(batch.size(), std::memory_order_relaxed);
    return;
  }
  buffer_.clear();
  for (const Entry& e : batch) {
    payload_.clear();
    switch (e.type) {
      case protocol::JournalRecordType::map_pose:
        protocol::encode_journal_pose(e.pose, payload_);
        break;
      case protocol::JournalRecordType::tile_points:
        protocol::encode_journal_tile_points(e.tile, payload_);
        break;
      case protocol::JournalRecordType::keyframe:
        protocol::encode_journal_keyframe({e.pose, e.body_points}, payload_);
        break;
      default:
        continue;
    }
    protocol::append_journal_record(buffer_, e.type, payload_);
  }
  write_bytes(buffer_);
  if (!failed_) stats_.records.fetch_add(batch.size(), std::memory_order_relaxed);
  else stats_.lost_records.fetch_add(batch.size(), std::memory_order_relaxed);
}

// Appends whole; on an error (ENOSPC) cuts the file back to its last whole
// record, so the journal stays readable to its end, and stops the journal.
void JournalWriter::write_bytes(std::span<const std::uint8_t> bytes) {
  if (failed_ || bytes.empty()) return;
  const off_t before = ::lseek(fd_, 0, SEEK_END);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string why = n < 0 ? std::strerror(errno) : "no progress";
      if (before >= 0 && ::ftruncate(fd_, before) != 0) {
        // The reader cuts a torn tail itself.
      }
      {
        const std::lock_guard lock(fault_mutex_);
        fault_ = fmt::format("session journal {}: {}: the journal stopped, the mapping goes on", file_.string(), why);
      }
      failed_ = true;
      log::error("{}", fault());
      return;
    }
    done += static_cast<std::size_t>(n);
  }
  stats_.bytes.fetch_add(bytes.size(), std::memory_order_relaxed);
  dirty_ = true;
}

void JournalWriter::sync() {
  if (fd_ >= 0 && ::fdatasync(fd_) == 0) stats_.syncs.fetch_add(1, std::memory_order_relaxed);
  dirty_ = false;
  last_sync_ns_ = monotonic_ns();
}

void JournalWriter::close(bool clean) {
  {
    const std::lock_guard lock(mutex_);
    if (closed_) return;
    closed_ = true;
    closing_ = true;
    clean_ = clean;
  }
  ready_.notify_one();
  thread_.join();
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

std::string JournalWriter::fault() const {
  const std::lock_guard lock(fault_mutex_);
  return fault_;
}

}  // namespace adit::daemon
