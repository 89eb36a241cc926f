#pragma once
// Live localisation against a prior map (prior_map.dir, docs/PRIOR-MAP.md):
// the odometry thread hands over its first scans, in the odometry frame,
// levelled by its up; thread "prior" (low priority: a search takes 1-3 s of a
// core) runs slam::localise on them; once found, the odometry thread takes the
// anchor (prior_from_odometry) and registers every later scan against the
// prior as well (slam::Odometry::anchor_to_prior). Two windows of scans: while
// a try searches one, the odometry thread gathers the next into the other, so
// the next try starts as soon as the search ends (decision 058). After the k-th
// failed try k·scans_per_try scans are passed over before the next window
// begins (at most 10×; none while a found pose waits to be confirmed: the prior
// matches there), so a prior that never matches (another building, a start
// outside it) costs a search every ~11 s at most, not one every second for the
// whole session. With `confirm`, a try that finds a pose is taken only once
// the next try that finds one agrees with it (slam::AnchorConfirmation, the
// sensor placed by both anchors); one that disagrees waits for the next in its
// turn. A crew's hint (HINT: set_hint, on the endpoint's thread) narrows the
// tries after it and starts the next window at once; it is held under a mutex
// the odometry thread never takes.
//
// Hand-off: two preallocated windows, each owned as its atomic state says
// (release/acquire): free, the odometry thread's (filling); ready, the prior
// thread's (waiting or searched). They are filled and searched in turn. The
// odometry thread never waits, locks or allocates per scan here: a scan that
// arrives while both windows are the prior thread's is passed over, and one
// that does not fit its window is cut.

#include <array>
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
// window begins: failures × scans_per_try, at most 10 × (the tries' spacing
// grows to 11 tries' worth); none while a found pose waits to be confirmed
// (the prior matches there). `adit bench prior-map` retries by the same rule.
int scans_passed_over(std::uint64_t failures, int scans_per_try, bool found_waiting = false);

class PriorLocaliser {
 public:
  // `scans_per_try`: scans gathered for one try; `max_points`: each window's
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
  // (none yet: the scan is skipped). Ignored while both windows are the prior
  // thread's, and once found.
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
  enum Progress : int { kSearching, kFound, kAnchored };
  enum WindowState : int { kFree, kReady };
  // One window of scans for a try.
  struct Window {
    std::vector<Eigen::Vector3f> cloud;  // odometry frame while filling, levelled once searched
    Eigen::Isometry3d level_from_odometry = Eigen::Isometry3d::Identity();
    double sensor_heading_rad = 0.0;  // the sensor's x in the levelled frame
    std::atomic<int> state{kFree};    // owner: the odometry thread while kFree, the prior thread while kReady
  };
  void loop();
  void write_frame(const Eigen::Isometry3d& prior_from_odometry) const;
  std::optional<slam::LocalisationHint> search_hint(const Window& window) const;

  const slam::PriorMap prior_;
  const slam::VoxelHashMap index_;
  const int scans_per_try_;
  const bool confirm_;
  const slam::LocalisationConfig localisation_;  // a confirmed pair's acceptance with confirm_
  slam::AnchorConfirmation confirmation_;  // prior thread: a found anchor waiting for the next try to agree
  std::filesystem::path frame_file_;
  std::atomic<int> progress_{kSearching};
  std::atomic<bool> finished_{false};  // join(): the pipeline has drained
  std::array<Window, 2> windows_;
  Eigen::Isometry3d anchor_ = Eigen::Isometry3d::Identity();  // written by the prior thread before kFound
  int filling_ = 0;  // odometry thread: the window it fills next
  int scans_ = 0;    // odometry thread: scans in that window
  int searching_ = 0;  // prior thread: the window it searches next
  // Scans to pass over before the next window begins: set by the prior thread
  // before it frees a window (released with its state), taken by the odometry thread.
  std::atomic<int> pass_over_{0};
  int skip_ = 0;                         // odometry thread: scans still to pass over before the next window
  std::int64_t first_stamp_ns_ = 0;  // odometry thread only
  mutable std::mutex hint_mutex_;  // the endpoint's thread sets, the prior thread reads: never the odometry's
  std::optional<protocol::LocaliseHint> hint_;
  std::atomic<bool> hint_arrived_{false};  // the odometry thread then begins the next window at once
  PriorLocaliserStats stats_;
  StageThread thread_;
};

}  // namespace adit::daemon
