// Thread "prior": localises the odometry's first scans against the prior map
// and hands the anchor back (prior_localiser.hpp).
#include "adit/daemon/prior_localiser.hpp"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <thread>

#include <fmt/format.h>

#include "adit/common/log.hpp"
#include "adit/daemon/session_frame.hpp"
#include "adit/slam/global_localisation.hpp"

namespace adit::daemon {
namespace {

constexpr int kNice = 10;  // below the stages, as the loop-closure thread
constexpr auto kPoll = std::chrono::milliseconds(50);
constexpr std::uint64_t kMaxBackoff = 10;  // tries' spacing grows to at most 11 × scans_per_try

}  // namespace

int scans_passed_over(std::uint64_t failures, int scans_per_try, bool found_waiting) {
  if (found_waiting) return 0;
  return scans_per_try * static_cast<int>(std::min<std::uint64_t>(failures, kMaxBackoff));
}

PriorLocaliser::PriorLocaliser(slam::PriorMap prior, int scans_per_try, std::size_t max_points,
                               const std::atomic<bool>& stop, bool confirm)
    : prior_(std::move(prior)),
      index_(slam::index_prior_map(prior_)),
      scans_per_try_(std::max(1, scans_per_try)),
      confirm_(confirm),
      localisation_(confirm ? slam::confirmed_localisation() : slam::LocalisationConfig{}),
      confirmation_(localisation_),
      thread_("prior", config::ThreadSettings{}, stop) {
  for (Window& w : windows_) w.cloud.reserve(max_points);
}

PriorLocaliser::~PriorLocaliser() { join(); }

void PriorLocaliser::start(const std::filesystem::path& frame_file) {
  frame_file_ = frame_file;
  thread_.start([this] { loop(); });
}

void PriorLocaliser::join() {
  finished_.store(true, std::memory_order_release);
  thread_.join();
}

void PriorLocaliser::add_scan(std::span<const Eigen::Vector3f> points, const Eigen::Isometry3d& sensor,
                              const std::optional<Eigen::Vector3d>& up, std::int64_t stamp_ns) {
  if (progress_.load(std::memory_order_acquire) != kSearching) return;
  Window& window = windows_[static_cast<std::size_t>(filling_)];
  if (window.state.load(std::memory_order_acquire) != kFree) return;  // both windows are the prior thread's
  // A failure's pass-over (posted before its window was freed) and a hint
  // count from the next window's beginning, not within one.
  if (const int n = pass_over_.exchange(0, std::memory_order_relaxed); n > 0) skip_ = n;
  if (hint_arrived_.exchange(false, std::memory_order_relaxed)) skip_ = 0;  // a new hint is tried at once
  if (scans_ == 0 && skip_ > 0) {
    --skip_;
    return;
  }
  if (!up) {
    stats_.scans_without_up.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  if (first_stamp_ns_ == 0) first_stamp_ns_ = stamp_ns;
  std::vector<Eigen::Vector3f>& cloud = window.cloud;
  const std::size_t room = cloud.capacity() - cloud.size();
  cloud.insert(cloud.end(), points.begin(), points.begin() + static_cast<std::ptrdiff_t>(std::min(room, points.size())));
  if (++scans_ < scans_per_try_) return;
  // A levelled frame at the sensor now, as a crew's start would be, and the
  // sensor's heading in it (a hint gives the heading in the prior's frame).
  window.level_from_odometry = slam::levelled_frame_at(*up, sensor.translation());
  const Eigen::Vector3d forward = window.level_from_odometry.linear() * sensor.linear().col(0);
  window.sensor_heading_rad = std::atan2(forward.y(), forward.x());
  scans_ = 0;
  window.state.store(kReady, std::memory_order_release);
  filling_ = 1 - filling_;
}

std::optional<Eigen::Isometry3d> PriorLocaliser::take_anchor(std::int64_t stamp_ns) {
  if (progress_.load(std::memory_order_acquire) != kFound) return std::nullopt;
  progress_.store(kAnchored, std::memory_order_relaxed);
  stats_.anchored_after_s.store(1e-9 * static_cast<double>(stamp_ns - first_stamp_ns_), std::memory_order_relaxed);
  stats_.anchored.store(true, std::memory_order_release);
  return anchor_;
}

void PriorLocaliser::loop() {
  if (setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), kNice) != 0)
    log::warn("prior: could not lower the thread's priority");
  bool said_no_up = false;
  while (!thread_.stopping() && !finished_.load(std::memory_order_acquire)) {
    thread_.beat.beat();
    if (!said_no_up && stats_.scans_without_up.load(std::memory_order_relaxed) >= static_cast<std::uint64_t>(scans_per_try_)) {
      log::warn("prior: the odometry has no gravity (no IMU or accelerometer yet), so its scans cannot be levelled "
                "for localisation; waiting for one");
      said_no_up = true;
    }
    Window& window = windows_[static_cast<std::size_t>(searching_)];
    if (window.state.load(std::memory_order_acquire) != kReady) {
      std::this_thread::sleep_for(kPoll);
      continue;
    }
    const Eigen::Isometry3f to_level = window.level_from_odometry.cast<float>();
    for (Eigen::Vector3f& p : window.cloud) p = to_level * p;
    const std::optional<slam::LocalisationHint> hint = search_hint(window);
    const slam::LocalisationResult found = slam::localise(window.cloud, prior_, index_, hint, localisation_);
    if (hint) stats_.hinted_tries.fetch_add(1, std::memory_order_relaxed);
    stats_.tries.fetch_add(1, std::memory_order_relaxed);
    window.cloud.clear();
    searching_ = 1 - searching_;
    if (!found.success) {
      log::info("prior: not localised yet ({}); trying again with later scans", found.failure);
      // Counted, then the window freed: the odometry thread sees the count and
      // the scans to pass over with it. None while a found pose waits.
      const std::uint64_t failures = stats_.failures.fetch_add(1, std::memory_order_relaxed) + 1;
      pass_over_.store(scans_passed_over(failures, scans_per_try_, confirmation_.waiting()), std::memory_order_relaxed);
      window.state.store(kFree, std::memory_order_release);
      continue;
    }
    const Eigen::Isometry3d anchor = found.pose * window.level_from_odometry;
    const Eigen::Vector3d t = found.pose.translation();
    const bool disagrees = confirmation_.waiting();
    if (confirm_ && !confirmation_.agrees(anchor, window.level_from_odometry.inverse())) {
      log::info("prior: found ({:.2f}, {:.2f}, {:.2f}) m in the prior's frame, overlap {:.2f}{}; taken once the next "
                "try agrees",
                t.x(), t.y(), t.z(), found.overlap, disagrees ? ", not where the try before found" : "");
      stats_.unconfirmed.fetch_add(1, std::memory_order_relaxed);
      window.state.store(kFree, std::memory_order_release);  // not a failure: nothing passed over
      continue;
    }
    anchor_ = anchor;
    log::info("prior: localised at ({:.2f}, {:.2f}, {:.2f}) m in the prior's frame, overlap {:.2f}, position sigma "
              "{:.3f} m{}; the odometry registers against the prior from its next scan",
              t.x(), t.y(), t.z(), found.overlap, found.position_sigma_m, confirm_ ? ", where the try before found" : "");
    write_frame(anchor_);
    progress_.store(kFound, std::memory_order_release);
    break;  // one anchor a session
  }
}

void PriorLocaliser::write_frame(const Eigen::Isometry3d& prior_from_odometry) const {
  if (frame_file_.empty()) return;
  try {
    write_prior_frame(frame_file_, prior_from_odometry);
  } catch (const std::exception& e) {
    log::error("prior: cannot write {}: {}", frame_file_.string(), e.what());
  }
}

std::string PriorLocaliser::set_hint(const protocol::LocaliseHint& hint) {
  if (progress_.load(std::memory_order_acquire) != kSearching) return "already localised in the prior map";
  {
    const std::lock_guard lock(hint_mutex_);
    hint_ = hint;
  }
  hint_arrived_.store(true, std::memory_order_relaxed);
  log::info("prior: hint ({:.1f}, {:.1f}) m within {:.1f} m, heading {}; the next try searches there only", hint.x_m,
            hint.y_m, hint.radius_m,
            hint.heading_deg ? fmt::format("{:.0f}° ± {:.0f}°", *hint.heading_deg, hint.heading_tolerance_deg) : "any");
  return {};
}

// Prior thread: the hint as the search takes it. Its heading is the sensor's;
// the search turns the window's levelled frame, whose x is the sensor's
// heading less its sensor_heading_rad.
std::optional<slam::LocalisationHint> PriorLocaliser::search_hint(const Window& window) const {
  const std::lock_guard lock(hint_mutex_);
  if (!hint_) return std::nullopt;
  slam::LocalisationHint h;
  h.position = Eigen::Vector2d(hint_->x_m, hint_->y_m);
  h.radius_m = hint_->radius_m;
  if (hint_->heading_deg) {
    h.yaw_rad = *hint_->heading_deg * std::numbers::pi / 180.0 - window.sensor_heading_rad;
    h.yaw_tolerance_rad = hint_->heading_tolerance_deg * std::numbers::pi / 180.0;
  } else {
    h.yaw_tolerance_rad = std::numbers::pi;  // any heading
  }
  return h;
}

std::optional<Eigen::Isometry3d> PriorLocaliser::anchor() const {
  if (progress_.load(std::memory_order_acquire) == kSearching) return std::nullopt;
  return anchor_;  // written before kFound was released, never after
}

}  // namespace adit::daemon
