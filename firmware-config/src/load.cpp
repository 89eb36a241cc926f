#include "adit/config/load.hpp"

#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "yaml_reader.hpp"
#include "yaml_writer.hpp"

namespace adit::config {
namespace {

using detail::ReadContext;
using detail::YamlReader;

// Rules that involve more than one key. `reader` only reports; `ctx.lines`
// gives the line where each key was written (or the section's, if absent).
void check_consistency(const Config& c, const ReadContext& ctx) {
  const auto fail = [&](const std::string& key, const std::string& fallback_key, const std::string& reason) {
    const auto it = ctx.lines.find(key);
    const auto fallback = ctx.lines.find(fallback_key);
    const int line = it != ctx.lines.end() ? it->second : fallback != ctx.lines.end() ? fallback->second : 1;
    throw InputError(fmt::format("{}:{}", ctx.file, line), key, reason);
  };

  if (c.prior_map.previous_session && !c.prior_map.dir.empty())
    fail("prior_map.previous_session", "prior_map", "choose one prior: prior_map.dir or the previous session's map");
  if (c.lidar.source == LidarSource::pcap && c.lidar.pcap.empty())
    fail("lidar.pcap", "lidar.source", "required when lidar.source is pcap");
  if (c.lidar.source == LidarSource::scan_dir && c.lidar.scan_dir.empty())
    fail("lidar.scan_dir", "lidar.source", "required when lidar.source is scan_dir");
  if (c.lidar.min_range_m >= c.lidar.max_range_m)
    fail("lidar.min_range_m", "lidar.model", "must be less than lidar.max_range_m");

  if (c.can.enabled && c.can.source == CanSource::candump && c.can.log.empty())
    fail("can.log", "can.source", "required when can.source is candump");
  for (std::size_t i = 0; i < c.can.signals.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (c.can.signals[i].name == c.can.signals[j].name)
        fail(fmt::format("can.signals[{}].name", i), "can.signals", "signal name is used twice");
  for (std::size_t i = 0; i < c.can.signals.size(); ++i) {
    const CanSignal& s = c.can.signals[i];
    if (s.value_type == ValueType::ieee_float && s.length != 32 && s.length != 64)
      fail(fmt::format("can.signals[{}].length", i), fmt::format("can.signals[{}].name", i),
           "must be 32 or 64 for value_type ieee_float");
    if (!s.extended && s.id > 0x7FF)
      fail(fmt::format("can.signals[{}].id", i), fmt::format("can.signals[{}].name", i),
           "exceeds 0x7FF; set extended: true for a 29-bit identifier");
  }

  if (c.wheel_odometry.enabled) {
    if (!c.can.enabled) fail("wheel_odometry.enabled", "wheel_odometry.enabled", "needs can.enabled: true");
    if (c.wheel_odometry.left_signal.empty())
      fail("wheel_odometry.left_signal", "wheel_odometry.enabled", "required when wheel odometry is enabled");
    if (c.wheel_odometry.right_signal.empty())
      fail("wheel_odometry.right_signal", "wheel_odometry.enabled", "required when wheel odometry is enabled");
  }

  if (c.imu.enabled) {
    const bool gyro = !c.imu.gyro_x_signal.empty() || !c.imu.gyro_y_signal.empty() || !c.imu.gyro_z_signal.empty();
    if (c.imu.source == ImuSource::ouster || c.imu.source == ImuSource::livox) {
      // The LiDAR's own IMU: its packets come with the LiDAR's.
      const bool ouster = c.imu.source == ImuSource::ouster;
      const bool lidar_has_it = ouster ? c.lidar.model.starts_with("OS") : c.lidar.model == "Mid-360" || c.lidar.model == "Avia";
      if (!lidar_has_it)
        fail("imu.source", "lidar.model",
             ouster ? "ouster needs an Ouster LiDAR (its IMU packets come with the LiDAR's), not " + c.lidar.model
                    : "livox needs a Livox LiDAR (lidar.model Mid-360 or Avia: its IMU packets come with the LiDAR's), not " +
                          c.lidar.model);
      if (c.lidar.source == LidarSource::scan_dir)
        fail("imu.source", "lidar.source", std::string(ouster ? "ouster" : "livox") +
                                               " reads the LiDAR's IMU packets: a scan directory has none");
      if (gyro || !c.imu.accel_x_signal.empty() || !c.imu.accel_y_signal.empty() || !c.imu.accel_z_signal.empty())
        fail("imu.source", "imu.source",
             std::string(ouster ? "ouster" : "livox") + " reads the LiDAR's IMU packets: give no CAN signals");
    } else {
      // The IMU is read by the CAN thread that integrates the wheels.
      if (!c.can.enabled) fail("imu.enabled", "imu.enabled", "needs can.enabled: true (the IMU is read from CAN)");
      // Without a gyroscope, the wheels give the acceleration to remove from the specific force.
      if (!gyro && !c.wheel_odometry.enabled)
        fail("imu.enabled", "imu.enabled",
             "an accelerometer alone needs wheel_odometry.enabled: true (the wheels give the acceleration to remove)");
      const std::pair<const char*, const std::string*> axes[] = {
          {"imu.accel_x_signal", &c.imu.accel_x_signal}, {"imu.accel_y_signal", &c.imu.accel_y_signal},
          {"imu.accel_z_signal", &c.imu.accel_z_signal}};
      for (const auto& [key, name] : axes)
        if (name->empty()) fail(key, "imu.enabled", "required when the IMU is enabled");
      if (gyro) {
        const std::pair<const char*, const std::string*> gyro_axes[] = {
            {"imu.gyro_x_signal", &c.imu.gyro_x_signal}, {"imu.gyro_y_signal", &c.imu.gyro_y_signal},
            {"imu.gyro_z_signal", &c.imu.gyro_z_signal}};
        for (const auto& [key, name] : gyro_axes)
          if (name->empty()) fail(key, "imu.gyro_x_signal", "give all three gyroscope signals or none");
      }
    }
  }

  if (c.map.tile_size_m / c.map.voxel_m > 1600.0)
    fail("map.voxel_m", "map.tile_size_m", "at most 1600 voxels per tile edge: raise map.voxel_m or lower map.tile_size_m");

  if (c.gpio.enabled) {
    const std::pair<const char*, const GpioLine*> lines[] = {
        {"gpio.button", &c.gpio.button}, {"gpio.status_led", &c.gpio.status_led}, {"gpio.lidar_power", &c.gpio.lidar_power}};
    for (const auto& [key, line] : lines) {
      if ((line->offset < 0) == line->name.empty())
        fail(fmt::format("{}.offset", key), "gpio.enabled", "give exactly one of offset or name");
    }
  }

  const std::pair<const char*, const ThreadSettings*> threads[] = {
      {"threads.receiver", &c.threads.receiver}, {"threads.odometry", &c.threads.odometry},
      {"threads.mapping", &c.threads.mapping}, {"threads.publisher", &c.threads.publisher}};
  for (const auto& [key, t] : threads) {
    if (t->policy == SchedPolicy::fifo && t->priority < 1)
      fail(fmt::format("{}.priority", key), fmt::format("{}.policy", key), "must be 1..99 with policy fifo");
    if (t->policy == SchedPolicy::other && t->priority != 0)
      fail(fmt::format("{}.priority", key), fmt::format("{}.policy", key), "must be 0 with policy other");
  }
}

// Made absolute, so that the configuration aditd saves into a session folder
// (config.yaml, read again there by the products) names the same files.
void resolve(std::string& path, const std::filesystem::path& base_dir) {
  if (!path.empty() && std::filesystem::path(path).is_relative())
    path = std::filesystem::absolute(base_dir / path).lexically_normal().string();
}

}  // namespace

Config parse_config(std::string_view yaml, const std::string& name, const std::filesystem::path& base_dir) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml));
  } catch (const YAML::ParserException& e) {
    throw InputError(fmt::format("{}:{}", name, e.mark.line + 1), "", fmt::format("not valid YAML: {}", e.msg));
  }
  ReadContext ctx{name, {}};
  if (root && !root.IsNull() && !root.IsMap())
    throw InputError(fmt::format("{}:1", name), "", "expected a mapping of sections at the top level");

  Config config;
  YamlReader reader(root, "", ctx, 1);
  describe(reader, config);
  reader.finish();
  check_consistency(config, ctx);

  for (std::string* path : {&config.lidar.pcap, &config.lidar.scan_dir, &config.lidar.calibration,
                            &config.can.log, &config.can.dbc, &config.payload.state_dir,
                            &config.prior_map.dir})
    resolve(*path, base_dir);
  // "$CREDENTIALS_DIRECTORY/…" is a systemd credential, resolved by aditd at run time.
  if (!config.lcm.key_file.starts_with('$')) resolve(config.lcm.key_file, base_dir);
  // A prior named but not prepared is caught here, before a flight (the
  // file's contents are checked by aditd when it loads it).
  if (!config.prior_map.dir.empty() && !std::filesystem::is_regular_file(std::filesystem::path(config.prior_map.dir) / "prior_map.bin"))
    throw InputError(name, "prior_map.dir",
                     fmt::format("'{}' holds no prepared prior map (adit prior-map prepare IN --out DIR)", config.prior_map.dir));
  return config;
}

Config load_config(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), "", "cannot open configuration file");
  std::stringstream text;
  text << in.rdbuf();
  return parse_config(text.str(), file.string(), file.parent_path());
}

std::string to_yaml(const Config& config) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  Config copy = config;  // describe() takes mutable references; the writer only reads
  detail::YamlWriter writer(out);
  describe(writer, copy);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace adit::config
