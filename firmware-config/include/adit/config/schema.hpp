#pragma once
// The configuration schema, written once: for each section, which keys exist,
// which are required and what values they accept. The same description drives
// the YAML reader (validation, with file/line/key errors) and the writer
// (`adit config show`), so keys, checks and defaults cannot drift apart.
//
// A visitor V provides:
//   v.required(key, value, check...)  a key that must be present
//   v.optional(key, value, check...)  a key that keeps its default when absent
//   v.section(key, sub)               a nested mapping, described by describe(v, sub)
//   v.list(key, items)                a sequence of mappings
// Checks: Range{lo, hi} for numbers, OneOf for strings, Names<E> for enums.

#include <array>
#include <span>
#include <string_view>
#include <utility>

#include "adit/config/config.hpp"

namespace adit::config {

template <typename T>
struct Range {
  T lo;
  T hi;
};

struct OneOf {
  std::span<const std::string_view> allowed;
};

template <typename E>
struct Names {
  std::span<const std::pair<std::string_view, E>> table;
};

// The LiDAR models the drivers decode. Ouster names follow "OS<range>-<beams>"; Livox: Mid-360 (SDK2), Avia (SDK1).
inline constexpr std::array<std::string_view, 24> kLidarModels{
    "VLP-16",     "VLP-32C",     "HDL-32E",      "VLS-128",     "RS-16",     "Helios16P",
    "PandarXT16", "PandarXT32",  "PandarXT32M",  "PandarQT64",  "PandarQT128", "Pandar40P",
    "Pandar64",   "OS0-32",      "OS0-64",       "OS0-128",     "OS1-32",    "OS1-64",
    "OS1-128",    "OS2-32",      "OS2-64",       "OS2-128",     "Mid-360",   "Avia"};

inline constexpr std::array<std::string_view, 3> kCanPresets{"", "canopen_tpdo", "odrive"};

inline constexpr std::array<std::pair<std::string_view, log::Level>, 6> kLogLevels{{
    {"trace", log::Level::trace}, {"debug", log::Level::debug}, {"info", log::Level::info},
    {"warn", log::Level::warn},   {"error", log::Level::error}, {"off", log::Level::off}}};
inline constexpr std::array<std::pair<std::string_view, LidarSource>, 3> kLidarSources{{
    {"udp", LidarSource::udp}, {"pcap", LidarSource::pcap}, {"scan_dir", LidarSource::scan_dir}}};
inline constexpr std::array<std::pair<std::string_view, ReturnMode>, 3> kReturnModes{{
    {"strongest", ReturnMode::strongest}, {"last", ReturnMode::last}, {"dual", ReturnMode::dual}}};
inline constexpr std::array<std::pair<std::string_view, CanSource>, 2> kCanSources{{
    {"socketcan", CanSource::socketcan}, {"candump", CanSource::candump}}};
inline constexpr std::array<std::pair<std::string_view, ByteOrder>, 2> kByteOrders{{
    {"intel", ByteOrder::intel}, {"motorola", ByteOrder::motorola}}};
inline constexpr std::array<std::pair<std::string_view, ValueType>, 3> kValueTypes{{
    {"unsigned", ValueType::unsigned_int}, {"signed", ValueType::signed_int}, {"ieee_float", ValueType::ieee_float}}};
inline constexpr std::array<std::pair<std::string_view, ImuSource>, 3> kImuSources{{
    {"can", ImuSource::can}, {"ouster", ImuSource::ouster}, {"livox", ImuSource::livox}}};
inline constexpr std::array<std::pair<std::string_view, DriveModel>, 2> kDriveModels{{
    {"differential", DriveModel::differential}, {"skid_steer", DriveModel::skid_steer}}};
inline constexpr std::array<std::pair<std::string_view, WheelQuantity>, 3> kWheelQuantities{{
    {"speed", WheelQuantity::speed}, {"angular_speed", WheelQuantity::angular_speed},
    {"counts", WheelQuantity::counts}}};
inline constexpr std::array<std::pair<std::string_view, SchedPolicy>, 2> kSchedPolicies{{
    {"other", SchedPolicy::other}, {"fifo", SchedPolicy::fifo}}};

template <typename V>
void describe(V& v, Transform& t) {
  v.optional("xyz_m", t.xyz_m, Range<double>{-100.0, 100.0});
  v.optional("rpy_deg", t.rpy_deg, Range<double>{-360.0, 360.0});
}

template <typename V>
void describe(V& v, PayloadSection& s) {
  v.required("id", s.id);
  v.optional("state_dir", s.state_dir);
}

template <typename V>
void describe(V& v, LogSection& s) {
  v.optional("level", s.level, Names<log::Level>{kLogLevels});
}

template <typename V>
void describe(V& v, LidarSection& s) {
  v.required("model", s.model, OneOf{kLidarModels});
  v.optional("source", s.source, Names<LidarSource>{kLidarSources});
  v.optional("pcap", s.pcap);
  v.optional("scan_dir", s.scan_dir);
  v.optional("replay_speed", s.replay_speed, Range<double>{0.0, 1000.0});
  v.optional("calibration", s.calibration);
  v.optional("address", s.address);
  v.optional("port", s.port, Range<int>{0, 65535});
  v.optional("imu_port", s.imu_port, Range<int>{0, 65535});
  v.optional("interface", s.interface);
  v.optional("multicast_group", s.multicast_group);
  v.optional("receive_buffer_bytes", s.receive_buffer_bytes, Range<int>{65536, 1 << 30});
  v.optional("return_mode", s.return_mode, Names<ReturnMode>{kReturnModes});
  v.optional("scan_cut_azimuth_deg", s.scan_cut_azimuth_deg, Range<double>{0.0, 360.0});
  v.optional("min_range_m", s.min_range_m, Range<double>{0.0, 10.0});
  v.optional("max_range_m", s.max_range_m, Range<double>{1.0, 2000.0});
  v.section("extrinsics", s.extrinsics);
}

template <typename V>
void describe(V& v, CanSignal& s) {
  v.required("name", s.name);
  v.required("id", s.id, Range<std::uint32_t>{0, 0x1FFFFFFF});
  v.optional("extended", s.extended);
  v.required("start_bit", s.start_bit, Range<int>{0, 511});
  v.required("length", s.length, Range<int>{1, 64});
  v.optional("byte_order", s.byte_order, Names<ByteOrder>{kByteOrders});
  v.optional("value_type", s.value_type, Names<ValueType>{kValueTypes});
  v.optional("factor", s.factor);
  v.optional("offset", s.offset);
  v.optional("unit", s.unit);
}

template <typename V>
void describe(V& v, CanSection& s) {
  v.optional("enabled", s.enabled);
  v.optional("source", s.source, Names<CanSource>{kCanSources});
  v.optional("interface", s.interface);
  v.optional("log", s.log);
  v.optional("dbc", s.dbc);
  v.optional("preset", s.preset, OneOf{kCanPresets});
  v.optional("node_id", s.node_id, Range<int>{0, 127});
  v.optional("record", s.record);
  v.list("signals", s.signals);
}

template <typename V>
void describe(V& v, WheelOdometrySection& s) {
  v.optional("enabled", s.enabled);
  v.optional("model", s.model, Names<DriveModel>{kDriveModels});
  v.optional("left_signal", s.left_signal);
  v.optional("right_signal", s.right_signal);
  v.optional("quantity", s.quantity, Names<WheelQuantity>{kWheelQuantities});
  v.optional("left_radius_m", s.left_radius_m, Range<double>{0.005, 5.0});
  v.optional("right_radius_m", s.right_radius_m, Range<double>{0.005, 5.0});
  v.optional("track_width_m", s.track_width_m, Range<double>{0.05, 10.0});
  v.optional("counts_per_revolution", s.counts_per_revolution, Range<int>{1, 1 << 24});
  v.optional("counter_bits", s.counter_bits, Range<int>{8, 64});
  v.optional("time_offset_s", s.time_offset_s, Range<double>{-10.0, 10.0});
  v.optional("max_acceleration_mps2", s.max_acceleration_mps2, Range<double>{0.5, 100.0});
  v.optional("max_slip_s", s.max_slip_s, Range<double>{0.0, 10.0});
}

template <typename V>
void describe(V& v, ImuSection& s) {
  v.optional("enabled", s.enabled);
  v.optional("source", s.source, Names<ImuSource>{kImuSources});
  v.optional("accel_x_signal", s.accel_x_signal);
  v.optional("accel_y_signal", s.accel_y_signal);
  v.optional("accel_z_signal", s.accel_z_signal);
  v.optional("gyro_x_signal", s.gyro_x_signal);
  v.optional("gyro_y_signal", s.gyro_y_signal);
  v.optional("gyro_z_signal", s.gyro_z_signal);
  v.optional("rpy_deg", s.rpy_deg, Range<double>{-360.0, 360.0});
  v.optional("position_m", s.position_m, Range<double>{-10.0, 10.0});
  v.optional("time_offset_s", s.time_offset_s, Range<double>{-10.0, 10.0});
  v.optional("accel_range_mps2", s.accel_range_mps2, Range<double>{0.0, 10'000.0});
  v.optional("gyro_range_radps", s.gyro_range_radps, Range<double>{0.0, 1'000.0});
  v.optional("gravity_sigma_deg", s.gravity_sigma_deg, Range<double>{0.01, 10.0});
  v.optional("gyro_with_wheels", s.gyro_with_wheels);
  v.optional("gyro_noise_density", s.gyro_noise_density, Range<double>{1e-6, 1.0});
  v.optional("accel_noise_density", s.accel_noise_density, Range<double>{1e-6, 10.0});
  v.optional("gyro_bias_walk", s.gyro_bias_walk, Range<double>{0.0, 1.0});
  v.optional("accel_bias_walk", s.accel_bias_walk, Range<double>{0.0, 10.0});
  v.optional("pose_horizon_s", s.pose_horizon_s, Range<double>{0.0, 10.0});
}

template <typename V>
void describe(V& v, GpioLine& s) {
  v.optional("offset", s.offset, Range<int>{-1, 1023});
  v.optional("name", s.name);
  v.optional("active_low", s.active_low);
}

template <typename V>
void describe(V& v, GpioSection& s) {
  v.optional("enabled", s.enabled);
  v.optional("chip", s.chip);
  v.section("button", s.button);
  v.section("status_led", s.status_led);
  v.section("lidar_power", s.lidar_power);
  v.optional("debounce_ms", s.debounce_ms, Range<int>{0, 1000});
}

inline constexpr std::array<std::string_view, 3> kMapFormats{"ply", "pcd", "las"};

template <typename V>
void describe(V& v, MapSection& s) {
  v.optional("tile_size_m", s.tile_size_m, Range<double>{1.0, 60.0});  // 1 mm quanta fit uint16
  v.optional("voxel_m", s.voxel_m, Range<double>{0.01, 1.0});
  v.optional("max_range_m", s.max_range_m, Range<double>{1.0, 1000.0});
  v.optional("min_hits", s.min_hits, Range<int>{1, 255});
  v.optional("publish_period_s", s.publish_period_s, Range<double>{0.1, 60.0});
  v.optional("keyframe_distance_m", s.keyframe_distance_m, Range<double>{0.1, 100.0});
  v.optional("keyframe_angle_deg", s.keyframe_angle_deg, Range<double>{1.0, 180.0});
  v.optional("keyframe_voxel_m", s.keyframe_voxel_m, Range<double>{0.05, 2.0});
  v.optional("evict_margin_m", s.evict_margin_m, Range<double>{0.0, 1000.0});
  v.optional("evict_after_keyframes", s.evict_after_keyframes, Range<int>{0, 1000000});
  v.optional("compact_tile_voxels", s.compact_tile_voxels, Range<int>{0, 100000000});
  v.optional("resident_tiles_mb", s.resident_tiles_mb, Range<double>{0.0, 1e6});
  v.optional("refine", s.refine);
  v.optional("loop_closure", s.loop_closure);
  v.optional("loops_move_map", s.loops_move_map);
  v.optional("merge_revisits", s.merge_revisits);
  v.optional("loops_tilt_walk", s.loops_tilt_walk);
  v.optional("loops_optimize_every_s", s.loops_optimize_every_s, Range<double>{0.0, 600.0});
}

template <typename V>
void describe(V& v, GridSection& s) {
  v.optional("enabled", s.enabled);
  v.optional("resolution_m", s.resolution_m, Range<double>{0.02, 1.0});
  v.optional("band_below_m", s.band_below_m, Range<double>{0.0, 10.0});
  v.optional("band_above_m", s.band_above_m, Range<double>{0.0, 10.0});
  v.optional("tilt_tolerance_deg", s.tilt_tolerance_deg, Range<double>{0.0, 10.0});
  v.optional("max_range_m", s.max_range_m, Range<double>{1.0, 200.0});
  v.optional("patch_cells", s.patch_cells, Range<int>{16, 200});  // 200² cells fit one message
  v.optional("publish_period_s", s.publish_period_s, Range<double>{0.1, 60.0});
  v.optional("refresh_s", s.refresh_s, Range<double>{1.0, 600.0});
}

template <typename V>
void describe(V& v, PriorMapSection& s) {
  v.optional("dir", s.dir);
  v.optional("previous_session", s.previous_session);
  v.optional("confirm", s.confirm);
}

template <typename V>
void describe(V& v, SessionSection& s) {
  v.optional("autostart", s.autostart);
  v.optional("record_lidar", s.record_lidar);
  v.optional("record_budget_mb", s.record_budget_mb, Range<double>{0.0, 1e9});
  v.optional("record_part_mb", s.record_part_mb, Range<double>{0.0, 4000.0});
  v.optional("record_min_free_mb", s.record_min_free_mb, Range<double>{0.0, 1e9});
  v.optional("exports", s.exports, OneOf{kMapFormats});
  v.optional("journal", s.journal);
  v.optional("journal_sync_s", s.journal_sync_s, Range<double>{0.05, 10.0});
  v.optional("keep_journal", s.keep_journal);
  v.optional("products", s.products);
  v.optional("join_previous", s.join_previous);
}

template <typename V>
void describe(V& v, LcmSection& s) {
  v.optional("url", s.url);
  v.optional("key_file", s.key_file);
  v.optional("command_window_s", s.command_window_s, Range<double>{1.0, 3600.0});
}

template <typename V>
void describe(V& v, ThreadSettings& s) {
  v.optional("policy", s.policy, Names<SchedPolicy>{kSchedPolicies});
  v.optional("priority", s.priority, Range<int>{0, 99});
  v.optional("cpu", s.cpu, Range<int>{-1, 1023});
}

template <typename V>
void describe(V& v, ThreadsSection& s) {
  v.optional("lock_memory", s.lock_memory);
  v.section("receiver", s.receiver);
  v.section("odometry", s.odometry);
  v.section("mapping", s.mapping);
  v.section("publisher", s.publisher);
}

template <typename V>
void describe(V& v, Config& c) {
  v.section("payload", c.payload);
  v.section("log", c.log);
  v.section("lidar", c.lidar);
  v.section("can", c.can);
  v.section("wheel_odometry", c.wheel_odometry);
  v.section("imu", c.imu);
  v.section("gpio", c.gpio);
  v.section("map", c.map);
  v.section("grid", c.grid);
  v.section("session", c.session);
  v.section("prior_map", c.prior_map);
  v.section("lcm", c.lcm);
  v.section("threads", c.threads);
}

}  // namespace adit::config
