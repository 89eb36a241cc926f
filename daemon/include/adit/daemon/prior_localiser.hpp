#pragma once
// Live localisation against a prior map (prior_map.dir, docs/PRIOR-MAP.md):
// the odometry thread hands over its first scans, in the odometry frame,
// levelled by its up; thread "prior" (low priority: a search takes 1-3 s of a
// core) runs slam::localise on them; once found, the odometry thread takes the
// anchor (prior_from_odometry) and registers every later scan against the
// prior as well (slam::Odometry::anchor_to_prior). A try that fails hands the
// buffer back and later scans are gathered for another: after the k-th failure
// k·scans_per_try scans are passed over first (at most 10×; none while a
// found pose waits to be confirmed: the prior matches there), so a prior that
// never matches (another building, a start outside it) costs a search every
// ~11 s at most, not one every second for the whole session. With `confirm`,
// a try that finds a pose is taken only once the next try that finds one
// agrees with it (slam::AnchorConfirmation, the sensor placed by both anchors); one
// that disagrees waits for the next in its turn. A crew's hint
// (HINT: set_hint, on the endpoint's thread) narrows the tries after it and
// starts the next at once; it is held under a mutex the odometry thread never takes.
//
// Hand-off: one preallocated cloud buffer whose owner is `state_` (an atomic,
// release/acquire): the odometry thread while filling and once found, the
// prior thread while localising. The odometry thread never waits, locks or
// allocates per scan here (a scan that does not fit the buffer is cut).

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "adit/daemon/stage_thread.hpp"
#include "adit/protocol/localise_hint.hpp"
#include "adit/slam/anchor_confirmation.hpp"
#include "adit/slam/global_localisation.hpp"
#include "adit/slam/prior_map.hpp"
#include "adit/slam/voxel_hash_map.hpp"

namespace adit::daemon {

struct PriorLocaliserStats {
  std::atomic<std::uint64_t> tries{0};
  std::atomic<std::uint64_t> failures{0};
  // Scans handed over before gravity was known (no IMU or accelerometer, or
  // not yet): they cannot be levelled, so they are not used.
  std::atomic<std::uint64_t> scans_without_up{0};
  std::atomic<std::uint64_t> hinted_tries{0};  // tries narrowed by a hint (HINT)
  // Tries that found a pose not yet taken: waiting for the next to agree, or
  // disagreeing with the one before (confirm).
  std::atomic<std::uint64_t> unconfirmed{0};
  std::atomic<bool> anchored{false};
  std::atomic<double> anchored_after_s{0.0};  // sensor time from the first scan handed over to the scan anchored from
};

// The scans passed over after the `failures`-th failed try before the next
// is gathered: failures × scans_per_try, at most 10 × (the tries' spacing
// grows to 11 tries' worth); none while a found pose waits to be confirmed
// (the prior matches there). `adit bench prior-map` retries by the same rule.
int scans_passed_over(std::uint64_t failures, int scans_per_try, bool found_waiting = false);

class PriorLocaliser {
 public:
  // `scans_per_try`: scans gathered for one try; `max_points`: the buffer's
  // room (a try with fewer points goes ahead when the scans are in);
  // `confirm`: a found pose waits for the next try to agree (prior_map.confirm).
  PriorLocaliser(slam::PriorMap prior, int scans_per_try, std::size_t max_points, const std::atomic<bool>& stop,
                 bool confirm = true);
  ~PriorLocaliser();
  PriorLocaliser(const PriorLocaliser&) = delete;
  PriorLocaliser& operator=(const PriorLocaliser&) = delete;

  // `frame_file`: where the anchor is written once found (JSON; empty: none).
  void start(const std::filesystem::path& frame_file);
  void join();

  // Odometry thread. `points`: the scan as it entered the map, odometry frame;
  // `sensor`: the sensor's pose (odometry frame); `up`: gravity's up there
  // (none yet: the scan is skipped). Ignored while a try runs or once anchored.
  void add_scan(std::span<const Eigen::Vector3f> points, const Eigen::Isometry3d& sensor,
                const std::optional<Eigen::Vector3d>& up, std::int64_t stamp_ns);
  // Any thread (HINT): later tries search only round `hint` (the sensor's
  // position and heading in the prior's frame), the next one at once; "" or
  // why not (already localised). A later hint replaces it.
  std::string set_hint(const protocol::LocaliseHint& hint);
  // Odometry thread: the anchor, once, when a try found it; `stamp_ns` is the
  // scan the odometry anchors from.
  std::optional<Eigen::Isometry3d> take_anchor(std::int64_t stamp_ns);
  // Any thread: prior_from_odometry once found (what prior_frame.json holds),
  // whether or not the odometry has taken it yet; it never changes after.
  std::optional<Eigen::Isometry3d> anchor() const;

  const slam::VoxelHashMap& index() const { return index_; }
  const PriorLocaliserStats& stats() const { return stats_; }
  const StageThread& thread() const { return thread_; }

 private:
  enum State : int { kFilling, kLocalising, kFound, kAnchored };
  void loop();
  void write_frame(const Eigen::Isometry3d& prior_from_odometry) const;
  std::optional<slam::LocalisationHint> search_hint() const;

  const slam::PriorMap prior_;
  const slam::VoxelHashMap index_;
  const int scans_per_try_;
  const bool confirm_;
  const slam::LocalisationConfig localisation_;  // a confirmed pair's acceptance with confirm_
  slam::AnchorConfirmation confirmation_;  // prior thread: a found anchor waiting for the next try to agree
  std::filesystem::path frame_file_;
  std::atomic<int> state_{kFilling};
  std::atomic<bool> finished_{false};  // join(): the pipeline has drained
  // Owned as state_ says.
  std::vector<Eigen::Vector3f> cloud_;
  Eigen::Isometry3d level_from_odometry_ = Eigen::Isometry3d::Identity();
  double sensor_heading_rad_ = 0.0;  // the sensor's x in the levelled frame
  Eigen::Isometry3d anchor_ = Eigen::Isometry3d::Identity();
  int scans_ = 0;
  // Scans to pass over before the next try: set by the prior thread before
  // it hands the buffer back (released with state_), taken by the odometry thread.
  std::atomic<int> pass_over_{0};
  int skip_ = 0;                         // odometry thread: scans still to pass over before the next try
  std::int64_t first_stamp_ns_ = 0;  // odometry thread only
  mutable std::mutex hint_mutex_;  // the endpoint's thread sets, the prior thread reads: never the odometry's
  std::optional<protocol::LocaliseHint> hint_;
  std::atomic<bool> hint_arrived_{false};  // the odometry thread then starts the next try at once
  PriorLocaliserStats stats_;
  StageThread thread_;
};

}  // namespace adit::daemon
