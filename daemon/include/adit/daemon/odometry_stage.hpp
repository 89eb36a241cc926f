#pragma once
// The pipeline's odometry stage: scans in, poses out.
//
// In:   ScanSlot from the LiDAR source (sensor frame), the CAN feed's wheel
//       samples and the IMU source's readings (CAN or Ouster) when configured.
// Out:  every scan's result (PoseSlot) to the output stage; each valid scan's
//       body-frame points, times and intensities with its pose (MapSlot) to
//       the mapping stage when mapping is on.
// Thread "odometry" runs ScanOdometry (scan_odometry.hpp) per scan: no
// allocation, lock or log per scan. Live, a full map hand-off drops the
// oldest scan (counted); a replay waits. Poses are never dropped.

#include <atomic>
#include <cstdint>
#include <optional>

#include "adit/config/config.hpp"
#include "adit/daemon/can_feed.hpp"
#include "adit/daemon/handoff.hpp"
#include "adit/daemon/pipeline_items.hpp"
#include "adit/daemon/pipeline_stats.hpp"
#include "adit/daemon/scan_odometry.hpp"
#include "adit/daemon/stage_thread.hpp"

namespace adit::daemon {

class PriorLocaliser;

class OdometryStage {
 public:
  // `max_points`: the most points a scan can hold (the map hand-off reserves
  // it); `overflow`: the map hand-off's policy (the source's).
  OdometryStage(const config::Config& config, const slam::OdometryConfig& odometry, Handoff<ScanSlot>& scans,
                CanFeed* can, ImuSource* imu, bool mapping, std::size_t max_points, Overflow overflow,
                PipelineStats& stats, PipelineTimings& timings, const std::atomic<bool>& stop);

  void start();
  void join() { thread_.join(); }

  Handoff<PoseSlot>& poses() { return poses_; }
  Handoff<MapSlot>* map_scans() { return map_slots_ ? &*map_slots_ : nullptr; }
  StageThread& thread() { return thread_; }
  const Handoff<ScanSlot>& input() const { return scans_; }
  // First and last scan stamps (after join()).
  std::int64_t first_stamp_ns() const { return first_stamp_ns_; }
  std::int64_t last_stamp_ns() const { return last_stamp_ns_; }
  // The IMU source's figures into the pipeline's stats (the odometry thread after each scan; anyone after join()).
  void copy_imu_stats();
  // Before start(): each LiDAR-inertial scan's filter state anchors the IMU-rate pose.
  void anchor_imu_poses_in(ImuPoseFeed* feed) { imu_poses_ = feed; }
  // Hands the first scans to `prior` and, once it localised them, registers
  // every later scan against the prior map too (prior_localiser.hpp). Before start().
  void localise_against(PriorLocaliser* prior) { prior_ = prior; }

 private:
  void loop();
  void hand_to_mapping(const drivers::LidarScan& scan, const slam::OdometryResult& result);

  Handoff<ScanSlot>& scans_;
  PipelineStats& stats_;
  PipelineTimings& timings_;
  StageThread thread_;
  ScanOdometry odometry_;
  Handoff<PoseSlot> poses_;
  std::optional<Handoff<MapSlot>> map_slots_;
  std::int64_t first_stamp_ns_ = 0;
  std::int64_t last_stamp_ns_ = 0;
  ImuPoseFeed* imu_poses_ = nullptr;
  PriorLocaliser* prior_ = nullptr;
  void follow_prior(const slam::OdometryResult& result);
};

}  // namespace adit::daemon
