#pragma once
// The payload configuration: every setting a program reads from YAML.
//
// The default values written here are the only defaults in the project; the
// schema (schema.hpp) names the keys, their checks and which are required.
// Relative paths are resolved against the configuration file's folder.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "adit/common/log.hpp"

namespace adit::config {

// A rigid transform, e.g. the sensor's pose in the body frame (x forward,
// y left, z up), rotation as roll-pitch-yaw in degrees (applied Z·Y·X).
struct Transform {
  std::array<double, 3> xyz_m{0.0, 0.0, 0.0};
  std::array<double, 3> rpy_deg{0.0, 0.0, 0.0};
};

struct PayloadSection {
  std::string id;                          // required: names this payload on the network
  std::string state_dir = "/var/lib/aditd";  // sessions, maps and recordings
};

struct LogSection {
  log::Level level = log::Level::info;
};

enum class LidarSource { udp, pcap, scan_dir };
enum class ReturnMode { strongest, last, dual };

struct LidarSection {
  std::string model;                     // required, e.g. VLP-16, PandarXT32, OS1-64
  LidarSource source = LidarSource::udp;
  std::string pcap;                      // source: pcap (required then)
  std::string scan_dir;                  // source: scan_dir (required then)
  double replay_speed = 1.0;             // pcap/scan_dir: × recorded rate; 0 = as fast as possible
  std::string calibration;               // Velodyne YAML, Hesai/RoboSense CSV, Ouster metadata JSON
  std::string address = "0.0.0.0";       // udp: local address to bind
  int port = 0;                          // udp: 0 = the model's default data port
  // udp and pcap: the port of the LiDAR's own IMU packets (imu.source ouster
  // or livox); 0 = the sensor's (Ouster: the metadata's udp_port_imu; Mid-360:
  // 56401; Avia: among the points, on the data port).
  int imu_port = 0;
  std::string interface;                 // udp: bind to this interface (empty = any)
  std::string multicast_group;           // udp: join this group (empty = unicast)
  int receive_buffer_bytes = 16 << 20;   // udp: SO_RCVBUF
  ReturnMode return_mode = ReturnMode::strongest;
  double scan_cut_azimuth_deg = 0.0;
  double min_range_m = 0.3;
  double max_range_m = 120.0;
  Transform extrinsics;                  // sensor in body frame
};

enum class CanSource { socketcan, candump };
enum class ByteOrder { intel, motorola };
enum class ValueType { unsigned_int, signed_int, ieee_float };

// A signal written inline, for payloads without a DBC (same fields as DBC SG_).
struct CanSignal {
  std::string name;          // required
  std::uint32_t id = 0;      // required: CAN identifier
  bool extended = false;     // 29-bit identifier
  int start_bit = 0;         // DBC convention for the byte order
  int length = 16;
  ByteOrder byte_order = ByteOrder::intel;
  ValueType value_type = ValueType::unsigned_int;  // ieee_float: length 32 or 64
  double factor = 1.0;
  double offset = 0.0;
  std::string unit;
};

struct CanSection {
  bool enabled = false;
  CanSource source = CanSource::socketcan;
  std::string interface = "can0";        // socketcan
  std::string log;                       // candump: -L log to replay (required then)
  std::string dbc;                       // a DBC file with the signals (or inline signals)
  std::string preset;                    // "", canopen_tpdo, odrive
  int node_id = 1;                       // presets: CANopen / ODrive node
  bool record = true;                    // write the bus to the session folder (can.log, candump -L)
  std::vector<CanSignal> signals;
};

enum class DriveModel { differential, skid_steer };
enum class WheelQuantity { speed, angular_speed, counts };

struct WheelOdometrySection {
  bool enabled = false;
  DriveModel model = DriveModel::differential;
  std::string left_signal;               // required when enabled: DBC "MESSAGE.SIGNAL" or inline name
  std::string right_signal;              // required when enabled
  WheelQuantity quantity = WheelQuantity::speed;  // m/s, rad/s, or encoder counts
  double left_radius_m = 0.1;
  double right_radius_m = 0.1;
  double track_width_m = 0.5;
  int counts_per_revolution = 4096;      // quantity: counts
  int counter_bits = 32;                 // quantity: counts (wrap-around)
  double time_offset_s = 0.0;            // encoder clock minus LiDAR clock
  // A wheel whose speed changes faster than this slips (traction is about
  // µ·g: 4 m/s² for rubber on wet rock) and is held at its last trusted speed
  // for at most max_slip_s (slam/wheel_odometry.hpp).
  double max_acceleration_mps2 = 15.0;
  double max_slip_s = 1.0;
};

// The IMU: an accelerometer, and a gyroscope where the unit has one. From
// the CAN bus (three signals each, in m/s² and rad/s after the signals'
// factors), from the Ouster's own IMU packets (UDP port 7503 beside the
// LiDAR's, the axes from the metadata's imu_to_sensor) or from a Livox's
// (Mid-360: UDP port 56401; Avia: among its points; placed where the model's
// manual puts it, docs/LIDAR-LIVOX.md). An accelerometer
// alone gives gravity's direction for roll and pitch (slam/gravity.hpp, with
// the wheels' acceleration removed); with a gyroscope the odometry is
// LiDAR-inertial. The noise model is the datasheet's (Allan deviation)
// figures; the defaults are a MEMS unit's (ADIS16448, as in the EuRoC
// datasets' calibration).
enum class ImuSource { can, ouster, livox };

struct ImuSection {
  bool enabled = false;
  ImuSource source = ImuSource::can;
  std::string accel_x_signal;            // CAN: required when enabled: DBC "MESSAGE.SIGNAL" or inline name
  std::string accel_y_signal;
  std::string accel_z_signal;
  std::string gyro_x_signal;             // CAN: all three or none (an accelerometer alone)
  std::string gyro_y_signal;
  std::string gyro_z_signal;
  std::array<double, 3> rpy_deg{0.0, 0.0, 0.0};     // the IMU's axes in the body frame (roll, pitch, yaw)
  std::array<double, 3> position_m{0.0, 0.0, 0.0};  // the IMU's origin in the body frame (lever arm)
  double time_offset_s = 0.0;            // IMU clock minus LiDAR clock
  // The unit's measuring range: a reading at or beyond it is counted
  // saturated (besides one at its CAN signal's encoding limit); 0 = no range.
  double accel_range_mps2 = 0.0;
  double gyro_range_radps = 0.0;
  double gravity_sigma_deg = 0.2;        // the odometry's trust in the measured up, per scan
  // With wheels and a gyroscope, the motion prior turns with the gyroscope
  // and moves with the wheels (gyrodometry, docs/decisions/052).
  bool gyro_with_wheels = true;
  double gyro_noise_density = 1.7e-4;    // rad/s/√Hz
  double accel_noise_density = 2.0e-3;   // m/s²/√Hz
  double gyro_bias_walk = 1.9e-5;        // rad/s²/√Hz
  double accel_bias_walk = 3.0e-3;       // m/s³/√Hz
  // The pose at the IMU's rate (LCM POSE_IMU, for a flight controller) goes
  // on this long past the latest LiDAR-inertial scan, then stops until the
  // next one (dead reckoning on a MEMS unit is metres off within seconds); 0 = none.
  double pose_horizon_s = 0.5;
};

// A GPIO line: by offset on the chip, or by its name (one of them).
struct GpioLine {
  int offset = -1;
  std::string name;
  bool active_low = false;
};

struct GpioSection {
  bool enabled = false;
  std::string chip = "gpiochip0";
  GpioLine button;
  GpioLine status_led;
  GpioLine lidar_power;
  int debounce_ms = 30;
};

// The session's global map (slam/tiled_map.hpp), its tiles on the tablet
// link (docs/PROTOCOL.md) and its keyframes (slam/keyframes.hpp).
struct MapSection {
  double tile_size_m = 20.0;
  double voxel_m = 0.05;                 // one point kept per voxel
  double max_range_m = 40.0;             // farther points stay out of the map (angular error grows with range)
  int min_hits = 2;                      // a voxel enters the map once hit this often (1 = at once)
  double publish_period_s = 1.0;         // changed tiles go out at most this often
  double keyframe_distance_m = 1.0;
  double keyframe_angle_deg = 10.0;
  double keyframe_voxel_m = 0.2;         // a keyframe's scan is downsampled to this
  // Tiles the sensor has left (farther than max_range_m + evict_margin_m for
  // evict_after_keyframes keyframes in a row) are written to the session's
  // tiles/ folder and leave RAM; 0 keyframes = keep every tile in RAM.
  double evict_margin_m = 10.0;
  int evict_after_keyframes = 20;
  // A tile holding more voxels than this in RAM (the sensor stays near it or
  // keeps coming back) is written out and keeps one bit per voxel; 0 = never.
  int compact_tile_voxels = 100'000;
  // The resident tiles' budget (MB): over it, the largest are written out the
  // same way until they hold three quarters of it; 0 = no budget.
  double resident_tiles_mb = 32.0;
  // Each scan's pose is refined against a dense map of the scans mapped
  // before it (slam::MapRefiner) before it enters the map; false = the map
  // takes the odometry's poses as they are.
  bool refine = true;
  // Keyframes go to the loop-closure thread (Scan Context, verification by
  // registration, a Ceres pose graph: docs/LOOPS.md); keyframes.tum holds
  // the graph's poses and summary.json the loops. false = no such thread.
  bool loop_closure = true;
  // The exported map and the live tiles follow the graph: each point moves
  // by the correction at its scan's time. On by default since decision 056
  // (over 30 simulated drives the map within 5 cm gains in mean and worst,
  // most on the long drives that close loops); false = the map as the
  // mapping thread placed it, the graph's poses in keyframes.tum only.
  bool loops_move_map = true;
  // With loops_move_map: a point whose place an earlier pass mapped (by the
  // graph) is not added again, so a route driven again does not add itself
  // beside the first pass by the drift (slam/revisit_filter.hpp). Off by
  // default: on the 30-minute drives the merged map lost 3-7 points within
  // 5 cm and the soak's shape check on seed 2 failed (decision 068).
  bool merge_revisits = false;
  // With an IMU, the graph lets the keyframes' measured up wander as the
  // accelerometer's bias walks (imu.accel_bias_walk): a loop that closes in
  // height then levels the route (docs/LOOPS.md). false = the ups as measured.
  bool loops_tilt_walk = true;
  // Loops found within this many seconds of the last graph optimisation wait
  // and are solved together (slam::LoopClosureConfig::optimize_every_s,
  // decision 062): the graph's CPU on a route driven again. 0 = at once.
  double loops_optimize_every_s = 5.0;
};

// The live 2D occupancy grid (slam::LiveGrid, docs/PRODUCTS.md "The live
// grid"): a slice of the world at the sensor's height, by ray casting each
// mapped scan; its changed patches go to the tablet on GRID, and the session
// folder gets it as grid_live.pgm / .yaml at the end.
struct GridSection {
  bool enabled = true;
  double resolution_m = 0.05;
  double band_below_m = 0.5;      // the slice, relative to the sensor's height
  double band_above_m = 0.5;
  double tilt_tolerance_deg = 1.0;  // the band narrows with range by this much attitude error
  double max_range_m = 40.0;      // horizontal reach of the rays
  int patch_cells = 128;          // cells per side of a patch (one message)
  double publish_period_s = 1.0;  // changed patches go out at most this often
  double refresh_s = 10.0;        // every patch goes out again within this (late or lossy clients)
};

// Sessions: what is kept in the session folder and how a session begins.
struct SessionSection {
  bool autostart = false;                // start mapping at launch (payloads without a tablet)
  // The raw LiDAR packets (the Ouster's IMU packets with them) to
  // <session>/lidar.pcap, so that a session can be mapped again (`adit
  // replay --session`); packet sources only. The recording stops (and the
  // status says so; the mapping goes on) when it reaches record_budget_mb
  // (0 = no budget) or free disk space falls below record_min_free_mb.
  bool record_lidar = true;
  double record_budget_mb = 16000.0;
  // The recording goes on in a new file (lidar.1.pcap, lidar.2.pcap, ...) when
  // one would pass this: under FAT32's 4 GB, and a card's tail lost with a
  // file costs one part. 0 = one file. Replays read the parts as one.
  double record_part_mb = 2000.0;
  double record_min_free_mb = 1000.0;
  std::vector<std::string> exports{"ply", "las"};  // map files written when a session stops
  // The session journal (<session>/journal.adj): what mapping makes reaches
  // the disk as it is made, so that aditd rebuilds a session's map after a
  // crash (docs/SESSIONS.md); fdatasync at most every journal_sync_s.
  bool journal = true;
  double journal_sync_s = 0.5;
  bool keep_journal = false;  // after a clean stop (the map files hold it all then): for audits and tests
  // After a stop, the session's products (<session>/products: occupancy .bt,
  // 2D grid, top view, cross-sections, targets.csv) on a SCHED_IDLE thread
  // (daemon/products_worker.hpp, docs/PRODUCTS.md "In aditd").
  bool products = true;
  // After a stop, place the session's map into the newest earlier session's
  // map it overlaps (of the last three with a map.ply): <session>/joined.json,
  // and `adit sessions` says "joined to <id>" (products/session_join_files.hpp,
  // docs/LOOPS.md "Joining sessions"). About 30 s of SCHED_IDLE CPU a try.
  bool join_previous = false;
};

// A prior map (BIM export, design model, earlier survey) prepared by
// `adit prior-map prepare IN --out DIR` (docs/PRIOR-MAP.md): each session
// localises its first scans against it and then registers every scan against
// it too (daemon/prior_localiser.hpp).
struct PriorMapSection {
  std::string dir;  // the prepared folder (prior_map.bin); empty: no prior
  // Without `dir`: the newest finished session's map file is each session's
  // prior, so a survey carried on after a stop (a battery swap) continues in
  // the frame of the one before (docs/PRIOR-MAP.md, "The previous session").
  bool previous_session = false;
  // A found pose is taken once the next try finds the same (within 0.3 m and
  // 2°, localise()'s distinct-rival distances): a floor nearly symmetric under
  // a half turn can fit one try better where it was not built as designed
  // (docs/decisions/053-prior-localisation-confirmed.md).
  bool confirm = true;
};

struct LcmSection {
  std::string url = "udpm://239.255.76.67:7667?ttl=1";
  // Command authentication (docs/COMMAND-AUTH.md): a key file readable only by
  // aditd (`adit keygen`); "" = commands are not authenticated. A path that
  // starts with $CREDENTIALS_DIRECTORY/ names a systemd credential.
  std::string key_file;
  double command_window_s = 30;  // a signed command's time may differ this much from the payload's clock
};

enum class SchedPolicy { other, fifo };

struct ThreadSettings {
  SchedPolicy policy = SchedPolicy::other;
  int priority = 0;   // SCHED_FIFO priority, 1..99
  int cpu = -1;       // pin to this CPU; -1 = any
};

struct ThreadsSection {
  bool lock_memory = true;
  ThreadSettings receiver;
  ThreadSettings odometry;
  ThreadSettings mapping;
  ThreadSettings publisher;
};

struct Config {
  PayloadSection payload;
  LogSection log;
  LidarSection lidar;
  CanSection can;
  WheelOdometrySection wheel_odometry;
  ImuSection imu;
  GpioSection gpio;
  MapSection map;
  GridSection grid;
  SessionSection session;
  PriorMapSection prior_map;
  LcmSection lcm;
  ThreadsSection threads;
};

}  // namespace adit::config
