#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "adit/common/error.hpp"
#include "adit/config/load.hpp"
#include "shared_data.hpp"

namespace adit::config {
namespace {

constexpr const char* kMinimal =
    "payload:\n"
    "  id: test\n"
    "lidar:\n"
    "  model: VLP-16\n";

Config parse(const std::string& yaml) { return parse_config(yaml, "test.yaml", "/base"); }

// Parses `yaml`, expects an InputError, and returns it for inspection.
InputError parse_error(const std::string& yaml) {
  try {
    parse(yaml);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << yaml;
  return InputError("", "", "");
}

TEST(ConfigLoader, MinimalConfigTakesEveryDefaultFromTheStructs) {
  const Config c = parse(kMinimal);
  const Config defaults;
  EXPECT_EQ(c.payload.id, "test");
  EXPECT_EQ(c.lidar.model, "VLP-16");
  EXPECT_EQ(c.lidar.source, defaults.lidar.source);
  EXPECT_EQ(c.lidar.receive_buffer_bytes, defaults.lidar.receive_buffer_bytes);
  EXPECT_EQ(c.lcm.url, defaults.lcm.url);
  EXPECT_EQ(c.log.level, defaults.log.level);
  EXPECT_EQ(c.payload.state_dir, defaults.payload.state_dir);  // absolute: not re-based
}

TEST(ConfigLoader, UnknownKeyNamesFileLineKeyAndSuggestsTheClosestKey) {
  const InputError e = parse_error(std::string(kMinimal) + "  prot: 2368\n");
  EXPECT_EQ(e.where(), "test.yaml:5");
  EXPECT_EQ(e.key(), "lidar.prot");
  EXPECT_EQ(e.reason(), "unknown key (did you mean 'port'?)");
}

TEST(ConfigLoader, UnknownSectionIsRejected) {
  const InputError e = parse_error(std::string(kMinimal) + "lidra:\n  port: 1\n");
  EXPECT_EQ(e.where(), "test.yaml:5");
  EXPECT_EQ(e.key(), "lidra");
  EXPECT_EQ(e.reason(), "unknown key (did you mean 'lidar'?)");
}

TEST(ConfigLoader, WrongTypeNamesFileLineAndKey) {
  const InputError e = parse_error(std::string(kMinimal) + "  port: abc\n");
  EXPECT_EQ(e.where(), "test.yaml:5");
  EXPECT_EQ(e.key(), "lidar.port");
  EXPECT_EQ(e.reason(), "expected an integer, got 'abc'");
}

TEST(ConfigLoader, ListWhereAScalarBelongsIsAWrongType) {
  const InputError e = parse_error(std::string(kMinimal) + "  address: [1, 2]\n");
  EXPECT_EQ(e.key(), "lidar.address");
  EXPECT_EQ(e.reason(), "expected a string, got a list");
}

TEST(ConfigLoader, OutOfRangeValueIsRejectedWithTheRange) {
  const InputError e = parse_error(std::string(kMinimal) + "  port: 70000\n");
  EXPECT_EQ(e.where(), "test.yaml:5");
  EXPECT_EQ(e.reason(), "expected a value in [0, 65535], got 70000");
}

TEST(ConfigLoader, NonFiniteNumbersAreRejected) {
  const InputError e = parse_error(std::string(kMinimal) + "  max_range_m: nan\n");
  EXPECT_EQ(e.key(), "lidar.max_range_m");
  EXPECT_EQ(e.reason(), "expected a number, got 'nan'");
}

TEST(ConfigLoader, MissingRequiredKeyNamesTheEnclosingSectionsLine) {
  const InputError e = parse_error("payload:\n  id: x\nlidar:\n  port: 2368\n");
  EXPECT_EQ(e.where(), "test.yaml:4");
  EXPECT_EQ(e.key(), "lidar.model");
  EXPECT_EQ(e.reason(), "required key is missing");
}

TEST(ConfigLoader, MissingRequiredSectionIsReported) {
  const InputError e = parse_error("lidar:\n  model: VLP-16\n");
  EXPECT_EQ(e.key(), "payload.id");
  EXPECT_EQ(e.reason(), "required key is missing");
}

TEST(ConfigLoader, UnknownModelListsTheSupportedOnes) {
  const InputError e = parse_error("payload:\n  id: x\nlidar:\n  model: VLP-17\n");
  EXPECT_EQ(e.where(), "test.yaml:4");
  EXPECT_NE(e.reason().find("expected one of: VLP-16, VLP-32C"), std::string::npos) << e.reason();
}

TEST(ConfigLoader, EnumsAcceptOnlyTheirNames) {
  EXPECT_EQ(parse(std::string(kMinimal) + "  return_mode: dual\n").lidar.return_mode, ReturnMode::dual);
  const InputError e = parse_error(std::string(kMinimal) + "  return_mode: both\n");
  EXPECT_EQ(e.reason(), "expected one of: strongest, last, dual; got 'both'");
}

TEST(ConfigLoader, BooleansAreStrictTrueOrFalse) {
  EXPECT_TRUE(parse(std::string(kMinimal) + "can:\n  enabled: true\n").can.enabled);
  const InputError e = parse_error(std::string(kMinimal) + "can:\n  enabled: yes\n");
  EXPECT_EQ(e.key(), "can.enabled");
  EXPECT_EQ(e.reason(), "expected true or false, got 'yes'");
}

TEST(ConfigLoader, DuplicateKeysAreRejected) {
  const InputError e = parse_error(std::string(kMinimal) + "  port: 1\n  port: 2\n");
  EXPECT_EQ(e.where(), "test.yaml:6");
  EXPECT_EQ(e.reason(), "key is given twice");
}

TEST(ConfigLoader, SectionThatIsNotAMappingIsRejected) {
  const InputError e = parse_error(std::string(kMinimal) + "gpio: 5\n");
  EXPECT_EQ(e.key(), "gpio");
  EXPECT_EQ(e.reason(), "expected a mapping of keys");
}

TEST(ConfigLoader, InvalidYamlReportsTheLine) {
  const InputError e = parse_error("payload:\n  id: [unclosed\n");
  EXPECT_EQ(e.where().rfind("test.yaml:", 0), 0U);
  EXPECT_NE(e.reason().find("not valid YAML"), std::string::npos);
}

TEST(ConfigLoader, HexadecimalIntegersAreAcceptedForCanIds) {
  const Config c = parse(std::string(kMinimal) +
                         "can:\n  signals:\n    - name: a\n      id: 0x1AB\n      start_bit: 0\n      length: 8\n");
  ASSERT_EQ(c.can.signals.size(), 1U);
  EXPECT_EQ(c.can.signals[0].id, 0x1ABU);
}

TEST(ConfigLoader, ListElementsAreCheckedWithTheirIndex) {
  const InputError e = parse_error(std::string(kMinimal) +
                                   "can:\n  signals:\n    - name: a\n      id: 1\n      length: 8\n");
  EXPECT_EQ(e.key(), "can.signals[0].start_bit");
  EXPECT_EQ(e.reason(), "required key is missing");
}

TEST(ConfigLoader, ConditionalRequirementsNameTheMissingKey) {
  const InputError pcap = parse_error(std::string(kMinimal) + "  source: pcap\n");
  EXPECT_EQ(pcap.where(), "test.yaml:5");  // the line of lidar.source
  EXPECT_EQ(pcap.key(), "lidar.pcap");
  EXPECT_EQ(pcap.reason(), "required when lidar.source is pcap");

  const InputError wheels = parse_error(std::string(kMinimal) + "wheel_odometry:\n  enabled: true\n");
  EXPECT_EQ(wheels.key(), "wheel_odometry.enabled");
  EXPECT_EQ(wheels.reason(), "needs can.enabled: true");

  const InputError imu = parse_error(std::string(kMinimal) + "imu:\n  enabled: true\n");
  EXPECT_EQ(imu.key(), "imu.enabled");
  EXPECT_EQ(imu.reason(), "needs can.enabled: true (the IMU is read from CAN)");
  const std::string can_and_wheels = std::string(kMinimal) +
                                     "can:\n  enabled: true\n  source: candump\n  log: can.log\n"
                                     "wheel_odometry:\n  enabled: true\n  left_signal: l\n  right_signal: r\n";
  const InputError axis =
      parse_error(can_and_wheels + "imu:\n  enabled: true\n  accel_x_signal: ax\n  accel_y_signal: ay\n");
  EXPECT_EQ(axis.key(), "imu.accel_z_signal");
  EXPECT_EQ(axis.reason(), "required when the IMU is enabled");
  EXPECT_EQ(parse_error(can_and_wheels + "imu:\n  gravity_sigma_deg: 0\n").key(), "imu.gravity_sigma_deg");
  EXPECT_EQ(parse_error(can_and_wheels + "imu:\n  pose_horizon_s: -0.1\n").key(), "imu.pose_horizon_s");
  const std::string accel = "imu:\n  enabled: true\n  accel_x_signal: ax\n  accel_y_signal: ay\n  accel_z_signal: az\n";
  const InputError gyro = parse_error(can_and_wheels + accel + "  gyro_x_signal: gx\n  gyro_z_signal: gz\n");
  EXPECT_EQ(gyro.key(), "imu.gyro_y_signal");
  EXPECT_EQ(gyro.reason(), "give all three gyroscope signals or none");
  // An accelerometer alone needs the wheels' acceleration; with a gyroscope it does not.
  const std::string can_only = std::string(kMinimal) + "can:\n  enabled: true\n  source: candump\n  log: can.log\n";
  EXPECT_EQ(parse_error(can_only + accel).reason(),
            "an accelerometer alone needs wheel_odometry.enabled: true (the wheels give the acceleration to remove)");
  const Config inertial = parse(can_only + accel + "  gyro_x_signal: gx\n  gyro_y_signal: gy\n  gyro_z_signal: gz\n");
  EXPECT_EQ(inertial.imu.gyro_z_signal, "gz");
  const InputError ouster = parse_error(std::string(kMinimal) + "imu:\n  enabled: true\n  source: ouster\n");
  EXPECT_EQ(ouster.key(), "imu.source");
  EXPECT_EQ(ouster.reason(), "ouster needs an Ouster LiDAR (its IMU packets come with the LiDAR's), not VLP-16");
  // A Livox's own IMU: only with a Livox LiDAR, the error on imu.source's line.
  const std::string livox_imu = "imu:\n  enabled: true\n  source: livox\n";
  const InputError livox = parse_error(std::string(kMinimal) + livox_imu);
  EXPECT_EQ(livox.key(), "imu.source");
  EXPECT_EQ(livox.where(), "test.yaml:7");
  EXPECT_EQ(livox.reason(),
            "livox needs a Livox LiDAR (lidar.model Mid-360 or Avia: its IMU packets come with the LiDAR's), not VLP-16");
  EXPECT_EQ(parse_error("payload:\n  id: test\nlidar:\n  model: OS1-64\n" + livox_imu).key(), "imu.source");
  const std::string mid360 = "payload:\n  id: test\nlidar:\n  model: Mid-360\n";
  EXPECT_EQ(parse(mid360 + livox_imu).imu.source, ImuSource::livox);
  EXPECT_EQ(parse(mid360 + "  imu_port: 40001\n" + livox_imu).lidar.imu_port, 40001);
  EXPECT_EQ(parse_error(mid360 + "  imu_port: 70000\n" + livox_imu).key(), "lidar.imu_port");
  EXPECT_EQ(parse("payload:\n  id: test\nlidar:\n  model: Avia\n" + livox_imu).imu.source, ImuSource::livox);
  EXPECT_EQ(parse_error(mid360 + livox_imu + "  accel_x_signal: ax\n").reason(),
            "livox reads the LiDAR's IMU packets: give no CAN signals");
  EXPECT_EQ(parse_error("payload:\n  id: test\nlidar:\n  model: Mid-360\n  source: scan_dir\n  scan_dir: scans\n" +
                        livox_imu)
                .reason(),
            "livox reads the LiDAR's IMU packets: a scan directory has none");

  const InputError fifo = parse_error(std::string(kMinimal) + "threads:\n  odometry:\n    policy: fifo\n");
  EXPECT_EQ(fifo.key(), "threads.odometry.priority");
}

TEST(ConfigLoader, SessionExportsAreAListOfKnownFormatsEachOnce) {
  EXPECT_EQ(parse(std::string(kMinimal) + "session:\n  exports: [pcd]\n").session.exports,
            std::vector<std::string>{"pcd"});
  const InputError unknown = parse_error(std::string(kMinimal) + "session:\n  exports: [ply, xyz]\n");
  EXPECT_EQ(unknown.key(), "session.exports[1]");
  EXPECT_EQ(unknown.reason(), "expected one of: ply, pcd, las; got 'xyz'");
  const InputError twice = parse_error(std::string(kMinimal) + "session:\n  exports: [las, las]\n");
  EXPECT_EQ(twice.reason(), "'las' is listed twice");
  EXPECT_EQ(parse_error(std::string(kMinimal) + "session:\n  exports: ply\n").reason(),
            "expected a list, e.g. [ply, las]");
}

TEST(ConfigLoader, MapVoxelsPerTileAreBounded) {
  const InputError e = parse_error(std::string(kMinimal) + "map:\n  tile_size_m: 50\n  voxel_m: 0.02\n");
  EXPECT_EQ(e.key(), "map.voxel_m");
  EXPECT_NO_THROW(parse(std::string(kMinimal) + "map:\n  tile_size_m: 50\n  voxel_m: 0.05\n"));
}

TEST(ConfigLoader, GpioLinesNeedExactlyOneOfOffsetOrName) {
  const std::string base = std::string(kMinimal) + "gpio:\n  enabled: true\n  button:\n    offset: 3\n"
                                                   "  status_led:\n    name: LED\n";
  const InputError e = parse_error(base + "  lidar_power:\n    offset: 4\n    name: PWR\n");
  EXPECT_EQ(e.key(), "gpio.lidar_power.offset");
  EXPECT_NO_THROW(parse(base + "  lidar_power:\n    offset: 4\n"));
}

TEST(ConfigLoader, RelativePathsAreResolvedAgainstTheConfigFolder) {
  const Config c = parse(std::string(kMinimal) + "  source: pcap\n  pcap: ../sessions/a.pcap\n");
  EXPECT_EQ(c.lidar.pcap, "/sessions/a.pcap");
}

// A configuration read from a relative folder (`aditd --config firmware-config/default.yaml`) names its
// files absolutely: aditd saves it into the session folder, where it is read again (the products).
TEST(ConfigLoader, PathsFromARelativeConfigFolderBecomeAbsolute) {
  const Config c = parse_config(std::string(kMinimal) + "  source: pcap\n  pcap: ../sessions/a.pcap\n", "relative.yaml",
                                "firmware-config");
  EXPECT_EQ(c.lidar.pcap, (std::filesystem::current_path() / "sessions/a.pcap").string());
}

TEST(ConfigLoader, KeyFileIsResolvedAgainstTheConfigFolderUnlessACredential) {
  Config c = parse(std::string(kMinimal) + "lcm:\n  key_file: ../keys/command.key\n");
  EXPECT_EQ(c.lcm.key_file, "/keys/command.key");
  EXPECT_EQ(c.lcm.command_window_s, 30.0);
  c = parse(std::string(kMinimal) + "lcm:\n  key_file: $CREDENTIALS_DIRECTORY/command-key\n  command_window_s: 5\n");
  EXPECT_EQ(c.lcm.key_file, "$CREDENTIALS_DIRECTORY/command-key");
  EXPECT_EQ(c.lcm.command_window_s, 5.0);
  EXPECT_EQ(parse(kMinimal).lcm.key_file, "") << "no key by default: commands are not authenticated";
}

TEST(ConfigLoader, EffectiveYamlReadsBackToTheSameConfiguration) {
  const std::filesystem::path file = test::source_dir() / "firmware-config/templates/vlp16-diffdrive-robot.yaml";
  const Config original = load_config(file);
  const std::string yaml = to_yaml(original);
  const Config again = parse_config(yaml, "effective.yaml", "/");
  EXPECT_EQ(to_yaml(again), yaml);
  EXPECT_EQ(again.can.signals.size(), 2U);
  EXPECT_EQ(again.threads.odometry.priority, 70);
}

TEST(ConfigLoader, MissingFileIsAnInputErrorNamingIt) {
  try {
    load_config("/nonexistent/payload.yaml");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "/nonexistent/payload.yaml");
  }
}

TEST(ShippedConfigs, EveryFileInFirmwareConfigIsValid) {
  int count = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(test::source_dir() / "firmware-config")) {
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    EXPECT_NO_THROW(load_config(entry.path())) << entry.path();
  }
  EXPECT_GE(count, 2);
}

}  // namespace
}  // namespace adit::config

namespace adit::config {
namespace {

TEST(ConfigLoader, PriorMapMustBeAPreparedFolder) {
  EXPECT_TRUE(parse_config(kMinimal, "test.yaml", "/base").prior_map.dir.empty());
  try {
    parse_config(std::string(kMinimal) + "prior_map:\n  dir: no-such-prior\n", "test.yaml", "/base");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("prior_map.dir"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("/base/no-such-prior"), std::string::npos) << e.what();
  }
  const auto dir = std::filesystem::temp_directory_path() / "adit_config_prior";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "prior_map.bin") << "x";
  EXPECT_EQ(parse_config(std::string(kMinimal) + "prior_map:\n  dir: " + dir.string() + "\n", "test.yaml", "/base").prior_map.dir,
            dir.string());
}

TEST(ConfigLoader, ThePreviousSessionOrAPriorDirectoryNotBoth) {
  EXPECT_FALSE(parse_config(kMinimal, "test.yaml", "/base").prior_map.previous_session);
  EXPECT_TRUE(parse_config(std::string(kMinimal) + "prior_map:\n  previous_session: true\n", "test.yaml", "/base")
                  .prior_map.previous_session);
  const auto dir = std::filesystem::temp_directory_path() / "adit_config_prior";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "prior_map.bin") << "x";
  try {
    parse_config(std::string(kMinimal) + "prior_map:\n  dir: " + dir.string() + "\n  previous_session: true\n",
                 "test.yaml", "/base");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "prior_map.previous_session") << e.what();
    EXPECT_NE(std::string(e.what()).find("choose one prior"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace adit::config
