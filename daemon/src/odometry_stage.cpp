// The odometry stage. In: scans from the LiDAR source, the CAN feed's
// samples. Out: every pose to the output stage, valid scans with their poses
// to the mapping stage. Thread odometry; no allocation, lock or log per scan;
// poses are never dropped. (odometry_stage.hpp)
#include "adit/daemon/odometry_stage.hpp"

#include "adit/common/clock.hpp"
#include "adit/daemon/imu_pose_feed.hpp"
#include "adit/daemon/prior_localiser.hpp"

namespace adit::daemon {

OdometryStage::OdometryStage(const config::Config& config, const slam::OdometryConfig& odometry,
                             Handoff<ScanSlot>& scans, CanFeed* can, ImuSource* imu, bool mapping,
                             std::size_t max_points, Overflow overflow, PipelineStats& stats, PipelineTimings& timings,
                             const std::atomic<bool>& stop)
    : scans_(scans),
      stats_(stats),
      timings_(timings),
      thread_("odometry", config.threads.odometry, stop),
      odometry_(config, odometry, can, imu, [this] { return thread_.idle(); },
                [this] { return !scans_.falling_behind(); }),
      poses_(kPoseSlots, Overflow::wait, [] { return PoseSlot{}; }) {
  if (mapping) {
    map_slots_.emplace(kMapSlots, overflow, [max_points] {
      MapSlot slot;
      slot.points.reserve(max_points);
      slot.times_s.reserve(max_points);
      slot.intensities.reserve(max_points);
      slot.sweep.reserve(slam::Odometry::kSweepMotionCapacity);
      return slot;
    });
  }
  timings_.odometry_ms.reserve(kTimingCapacity);
}

void OdometryStage::start() {
  thread_.start([this] { loop(); });
}

void OdometryStage::loop() {
  const auto idle = [this] { return thread_.idle(); };
  // A stop drops what is queued; the source's end is drained.
  while (!thread_.stopping()) {
    ScanSlot* slot = scans_.take_or_wait(idle);
    if (slot == nullptr) break;
    thread_.beat.beat();
    // The map starts from a full revolution: a stream joined mid-turn gives a
    // first scan that covers part of the view, and the next registration
    // against so small a map can settle tens of centimetres off, which a
    // LiDAR-inertial filter then takes for velocity. Only the first scan is
    // passed over: on a lossy link no scan may ever be complete.
    if (first_stamp_ns_ == 0 && !slot->scan.stats.complete &&
        stats_.skipped_start_scans.load(std::memory_order_relaxed) == 0) {
      stats_.skipped_start_scans.fetch_add(1, std::memory_order_relaxed);
      scans_.release(slot);
      continue;
    }
    const slam::OdometryResult& result = odometry_.process(slot->scan);
    if (imu_poses_ != nullptr && result.valid && result.inertial) imu_poses_->anchor(odometry_.inertial_state(), odometry_.inertial_covariance());
    const MotionAidCounts& counts = odometry_.counts();
    stats_.wheel_priors.store(counts.wheel_priors, std::memory_order_relaxed);
    stats_.scans_without_wheels.store(counts.scans_without_wheels, std::memory_order_relaxed);
    stats_.scans_wheels_held.store(counts.scans_wheels_held, std::memory_order_relaxed);
    stats_.gyro_priors.store(counts.gyro_priors, std::memory_order_relaxed);
    stats_.gyro_still.store(counts.gyro_still, std::memory_order_relaxed);
    stats_.gyro_refused.store(counts.gyro_refused, std::memory_order_relaxed);
    stats_.gravity_priors.store(counts.gravity_priors, std::memory_order_relaxed);
    stats_.scans_without_gravity.store(counts.scans_without_gravity, std::memory_order_relaxed);
    copy_imu_stats();
    if (timings_.odometry_ms.size() < kTimingCapacity) timings_.odometry_ms.push_back(odometry_.registration_ms());
    if (first_stamp_ns_ == 0) first_stamp_ns_ = slot->scan.start_time_ns;
    last_stamp_ns_ = slot->scan.start_time_ns;

    if (PoseSlot* out = poses_.acquire_or_wait(idle)) {
      out->result = result;
      out->last_packet_mono_ns = slot->last_packet_mono_ns;
      out->pose_mono_ns = monotonic_ns();
      poses_.publish(out);
    }
    if (prior_ != nullptr && result.valid) follow_prior(result);
    if (map_slots_ && result.valid) hand_to_mapping(slot->scan, result);
    scans_.release(slot);
  }
  stats_.dropped_scans.store(scans_.dropped());
  poses_.close();
  if (map_slots_) map_slots_->close();
}

// Until anchored, each scan as it entered the map goes to the localiser
// (which ignores it while a try runs); once anchored, nothing per scan here.
void OdometryStage::follow_prior(const slam::OdometryResult& result) {
  slam::Odometry& odometry = odometry_.odometry();
  if (odometry.prior_from_odometry()) return;
  if (const std::optional<Eigen::Isometry3d> anchor = prior_->take_anchor(result.stamp_ns)) {
    odometry.anchor_to_prior(prior_->index(), *anchor);  // allocates the prior's plane buffer: once a session
    return;
  }
  const Eigen::Isometry3d sensor = result.pose * odometry_.extrinsic().cast<double>();
  prior_->add_scan(odometry.last_registered_points(), sensor, odometry.up(), result.stamp_ns);
}

void OdometryStage::copy_imu_stats() {
  if (const ImuSource* imu = odometry_.imu()) copy_stats(imu->imu_stats(), stats_.imu);
}

// Copies (no allocation: the slot's buffers are reserved).
void OdometryStage::hand_to_mapping(const drivers::LidarScan& scan, const slam::OdometryResult& result) {
  MapSlot* m = map_slots_->acquire_or_wait([this] { return thread_.idle(); });
  if (m == nullptr) return;
  m->stamp_ns = result.stamp_ns;
  m->pose = result.pose;
  m->valid = result.valid;
  m->inertial = result.inertial;
  m->anchored = odometry_.odometry().prior_from_odometry().has_value();
  m->points.assign(odometry_.body_points().begin(), odometry_.body_points().end());
  m->times_s.assign(odometry_.body_times().begin(), odometry_.body_times().end());
  m->intensities.clear();
  for (const drivers::LidarPoint& p : scan.points) m->intensities.push_back(p.intensity);
  m->up = odometry_.odometry().up();  // what the exports are levelled by (session_frame.hpp)
  if (result.inertial)
    m->sweep.assign(odometry_.odometry().sweep_motion().begin(), odometry_.odometry().sweep_motion().end());
  else
    m->sweep.clear();
  map_slots_->publish(m);
}

}  // namespace adit::daemon
