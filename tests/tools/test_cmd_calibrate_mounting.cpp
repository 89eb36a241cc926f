// adit calibrate-mounting run as a crew would: a simulated robot whose LiDAR
// sits turned on its bracket, its wheels in the CAN log, and the sensor's
// trajectory; the mounting found, printed as the config's lines; bad input
// refused with the file or key named.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <algorithm>
#include <array>
#include <sstream>
#include <string>

#include "run_program.hpp"
#include "shared_data.hpp"
#include "sim_sessions.hpp"

namespace {

namespace fs = std::filesystem;
using adit::test::CommandRun;
CommandRun adit(const std::string& arguments) { return adit::test::run_adit(arguments); }

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// `text` with its first `from` replaced by `to` (std::regex trips g++ 12's
// maybe-uninitialized warning in the sanitizer build).
std::string replace_first(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// The session's config with its extrinsics replaced by `xyz` and `rpy`: the
// two lines after `  extrinsics:`.
fs::path config_with_extrinsics(const fs::path& session, const std::string& name, const std::string& xyz,
                                const std::string& rpy) {
  std::istringstream in(read_text(session / "session.yaml"));
  std::ostringstream out;
  int replace = 0;
  for (std::string line; std::getline(in, line);) {
    if (replace == 2) line = "    xyz_m: [" + xyz + "]";
    if (replace == 1) line = "    rpy_deg: [" + rpy + "]";
    replace = line == "  extrinsics:" ? 2 : std::max(0, replace - 1);
    out << line << "\n";
  }
  const fs::path file = session / name;
  std::ofstream(file) << out.str();
  return file;
}

// The numbers of the printed config line `key: [a, b, c]`.
std::array<double, 3> printed(const std::string& output, const std::string& key) {
  const auto at = output.find(key + ": [");
  if (at == std::string::npos) return {1e9, 1e9, 1e9};
  std::string numbers = output.substr(at + key.size() + 3, output.find(']', at) - at - key.size() - 3);
  for (char& c : numbers)
    if (c == ',') c = ' ';
  std::istringstream in(numbers);
  std::array<double, 3> v{1e9, 1e9, 1e9};
  in >> v[0] >> v[1] >> v[2];
  return v;
}

class CmdCalibrateMounting : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    session_ = adit::test::simulated_session(
        "test-sessions/cmd-calibrate-mounting",
        "--scene building --platform robot --sensor VLP-16 --duration 60 --seed 2 --mount-rpy-deg 2 -4 3");
  }
  static fs::path session_;
};
fs::path CmdCalibrateMounting::session_;

TEST_F(CmdCalibrateMounting, TheSensorsTrueTrajectoryGivesItsMountingBack) {
  const std::string yaml = read_text(session_ / "session.yaml");
  ASSERT_NE(yaml.find("rpy_deg: [2, -4, 3]"), std::string::npos) << "the simulator writes the mounting as given";
  // The sensor's own trajectory is the body's under a config that puts the
  // sensor at the body's origin: the fit must then be the simulated mounting.
  const fs::path config = config_with_extrinsics(session_, "at-origin.yaml", "0, 0, 0", "0, 0, 0");
  // The robot's body origin is its axle, 0.1651 m above the floor.
  const CommandRun run = adit("calibrate-mounting --config " + config.string() + " --trajectory " +
                              (session_ / "truth_sensor.tum").string() + " --body-height 0.1651");
  ASSERT_EQ(run.status, 0) << run.output;
  const auto rpy = printed(run.output, "rpy_deg");
  const auto xyz = printed(run.output, "xyz_m");
  // Roll and pitch from the floor: to the floor, so the body's mean tilt on
  // its bumps over this drive (pitch -0.18°) is in them.
  EXPECT_NEAR(rpy[0], 2.0, 0.3) << run.output;
  EXPECT_NEAR(rpy[1], -4.0, 0.3) << run.output;
  EXPECT_NEAR(rpy[2], 3.0, 0.15) << run.output;
  EXPECT_NEAR(xyz[0], 0.20, 0.01) << run.output;  // the robot template's lever arm
  EXPECT_NEAR(xyz[1], 0.0, 0.01) << run.output;
  EXPECT_NEAR(xyz[2], 0.45, 0.01) << run.output;
  EXPECT_NE(run.output.find("configured 0.000"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("floor     in "), std::string::npos) << run.output;

  // Without the floor, roll and pitch come from the turns alone and the
  // height is the configured one, printed back.
  const CommandRun turns = adit("calibrate-mounting --config " + config.string() + " --trajectory " +
                                (session_ / "truth_sensor.tum").string() + " --no-floor");
  ASSERT_EQ(turns.status, 0) << turns.output;
  const auto turns_rpy = printed(turns.output, "rpy_deg");
  // scripts/bench-mounting.sh --no-floor: 0.23° mean, 1.66° worst over nine drives.
  EXPECT_NEAR(turns_rpy[0], 2.0, 1.0) << turns.output;
  EXPECT_NEAR(turns_rpy[1], -4.0, 1.0) << turns.output;
  EXPECT_EQ(printed(turns.output, "xyz_m")[2], 0.0) << turns.output;
}

TEST_F(CmdCalibrateMounting, BadInputIsRefusedNamingTheFileOrKey) {
  const fs::path config = config_with_extrinsics(session_, "nominal.yaml", "0, 0, 0.45", "0, 0, 0");
  const CommandRun missing = adit("calibrate-mounting --config " + config.string() + " --trajectory /nonexistent.tum");
  EXPECT_EQ(missing.status, 2) << missing.output;
  EXPECT_NE(missing.output.find("/nonexistent.tum"), std::string::npos) << missing.output;

  // Poses on another clock overlap no wheel sample.
  std::ifstream in(session_ / "truth_sensor.tum");
  std::ofstream shifted(session_ / "shifted.tum");
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    double t = 0.0;
    fields >> t;
    std::string rest;
    std::getline(fields, rest);
    shifted << std::fixed << (t - 5000.0) << rest << "\n";
  }
  shifted.close();
  const CommandRun other_clock =
      adit("calibrate-mounting --config " + config.string() + " --trajectory " + (session_ / "shifted.tum").string());
  EXPECT_EQ(other_clock.status, 2) << other_clock.output;
  EXPECT_NE(other_clock.output.find("--trajectory"), std::string::npos) << other_clock.output;
  EXPECT_NE(other_clock.output.find("moving windows"), std::string::npos) << other_clock.output;

  // A config without the wheels' CAN log.
  std::string text = read_text(config);
  text = replace_first(text, "can:\n  enabled: true", "can:\n  enabled: false");
  std::ofstream(session_ / "no-can.yaml") << text;
  const CommandRun no_can = adit("calibrate-mounting --config " + (session_ / "no-can.yaml").string() +
                                 " --trajectory " + (session_ / "truth_sensor.tum").string());
  EXPECT_EQ(no_can.status, 2) << no_can.output;
  EXPECT_NE(no_can.output.find("can.enabled"), std::string::npos) << no_can.output;
}

}  // namespace
