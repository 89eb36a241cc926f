#pragma once
// What the pipeline's stages hand each other through Handoff<T>
// (handoff.hpp): preallocated items, filled by one thread and read by the
// next, and the sinks through which results leave the pipeline.
//
//   LidarSource ─ScanSlot→ OdometryStage ─PoseSlot→ OutputStage → PipelineSinks::pose
//                                         └─MapSlot→ MappingStage → PipelineSinks::tile

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "adit/drivers/lidar/point.hpp"
#include "adit/slam/live_grid.hpp"
#include "adit/slam/odometry.hpp"
#include "adit/slam/tiled_map.hpp"

namespace adit::daemon {

// Items per hand-off.
inline constexpr std::size_t kScanSlots = 4;
inline constexpr std::size_t kPoseSlots = 8;
inline constexpr std::size_t kMapSlots = 4;

// A whole scan in the sensor frame, as the drivers assembled it.
struct ScanSlot {
  drivers::LidarScan scan;
  std::int64_t last_packet_mono_ns = 0;  // when its last packet was received (latency)
};

// The odometry's result for one scan.
struct PoseSlot {
  slam::OdometryResult result;
  std::int64_t last_packet_mono_ns = 0;
  std::int64_t pose_mono_ns = 0;  // when the odometry handed it on
};

// A registered scan for the mapping thread: body-frame points as measured
// (not deskewed: mapping deskews with the corrected motion), with the pose.
struct MapSlot {
  std::int64_t stamp_ns = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  bool valid = false;
  bool inertial = false;  // the pose is the LiDAR-inertial odometry's
  bool anchored = false;  // the pose was registered against a prior map too (slam::Odometry::anchor_to_prior)
  std::vector<Eigen::Vector3f> points;
  std::vector<float> times_s;
  std::vector<float> intensities;
  // An inertial scan's motion over its sweep as the odometry deskewed it (the
  // IMU's, after the scan's update; slam::Odometry::sweep_motion); empty:
  // the mapping deskews with the constant velocity between its pose and the next.
  std::vector<slam::TimedPose> sweep;
  // Gravity's up in the odometry frame as the odometry measures it now
  // (slam::Odometry::up); nullopt before it has one, or without an IMU or accelerometer.
  std::optional<Eigen::Vector3d> up;
};

// Where results leave the pipeline. Each runs on one pipeline thread and must
// be quick and not throw; empty = not wanted.
struct PipelineSinks {
  using PoseSink = std::function<void(const slam::OdometryResult&)>;
  // A tile's points from `first_point` on (0: the whole tile); true when
  // taken (false: dropped, so the next update goes whole).
  using TileSink = std::function<bool(const slam::TileCoord&, std::size_t first_point, std::span<const slam::MapSample>)>;
  using ImuPoseSink = std::function<void(const slam::InertialState&, const slam::Matrix6d& covariance)>;
  // A live-grid patch whose cells changed: its coordinate, version, cells
  // (slam::LiveGrid::read) and the grid's patch count.
  using GridSink = std::function<void(slam::GridPatchCoord, std::int32_t version, std::span<const std::int8_t> cells,
                                      std::size_t patches)>;
  PoseSink pose;  // output thread, once per scan (valid or not)
  // The IMU source's thread, per IMU reading while LiDAR-inertial (imu_pose_feed.hpp): quick, never throws.
  ImuPoseSink imu_pose;
  TileSink tile;  // mapping thread: what a tile gained since its last update, or its whole content
  // Any thread: points handed to `tile` that its consumer has not taken yet
  // (the LCM thread's queue); the mapping thread holds back re-sends while
  // they are many (MappingStage::kTileBacklogPoints). Empty: not measured.
  std::function<std::uint64_t()> tile_backlog;
  GridSink grid;  // mapping thread, at most once per grid.publish_period_s per patch
};

}  // namespace adit::daemon
