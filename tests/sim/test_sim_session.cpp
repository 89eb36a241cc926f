// Determinism, the CAN log decoded back, the replay config, and bad options.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>
#include <vector>

#include "adit/common/error.hpp"
#include "adit/config/load.hpp"
#include "adit/drivers/can/candump.hpp"
#include "adit/drivers/can/decoder.hpp"
#include "adit/drivers/can/signal.hpp"
#include "adit/sim/imu.hpp"
#include "adit/sim/session.hpp"
#include "sim_session.hpp"

namespace adit::sim {
namespace {

std::string slurp(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(SimSession, SameSeedAndOptionsGiveIdenticalFilesWhateverTheThreads) {
  SimOptions a = test::short_session("same-a");
  a.threads = 1;
  SimOptions b = test::short_session("same-b");
  b.threads = 2;
  run_simulation(a);
  run_simulation(b);
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(a.out)) {
    const auto name = entry.path().filename();
    const std::string mine = slurp(entry.path());
    EXPECT_FALSE(mine.empty()) << name;
    EXPECT_TRUE(mine == slurp(b.out / name)) << name << " differs";
    ++files;
  }
  EXPECT_EQ(files, 9u);
  // A different seed gives a different scene and capture.
  SimOptions c = test::short_session("other-seed");
  c.seed = 8;
  run_simulation(c);
  EXPECT_NE(slurp(a.out / "lidar.pcap"), slurp(c.out / "lidar.pcap"));
  EXPECT_NE(slurp(a.out / "scene.ply"), slurp(c.out / "scene.ply"));
}

// The OS1-64 too: its pcap and metadata are the same bytes on 1 and 2 threads.
TEST(SimSession, Os164IsDeterministicWhateverTheThreads) {
  SimOptions a = test::short_session("same-os1-a");
  a.sensor = "OS1-64";
  a.wheels = false;
  a.threads = 1;
  SimOptions b = a;
  b.out = test::short_session("same-os1-b").out;
  b.threads = 2;
  run_simulation(a);
  run_simulation(b);
  for (const char* name : {"lidar.pcap", "OS1-64.json", "session.yaml"}) {
    const std::string mine = slurp(a.out / name);
    EXPECT_FALSE(mine.empty()) << name;
    EXPECT_TRUE(mine == slurp(b.out / name)) << name << " differs";
  }
  const auto config = config::load_config(a.out / "session.yaml");
  EXPECT_EQ(config.lidar.model, "OS1-64");
  EXPECT_TRUE(config.lidar.calibration.ends_with("OS1-64.json"));
}

struct WheelTruthRow {
  double t, left, right;
};

std::vector<WheelTruthRow> read_truth(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);  // header
  std::vector<WheelTruthRow> rows;
  while (std::getline(in, line)) {
    WheelTruthRow r{};
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf", &r.t, &r.left, &r.right) == 3) rows.push_back(r);
  }
  return rows;
}

TEST(SimSession, CanLogDecodesBackToTheWheelSpeedsWithinQuantisation) {
  SimOptions o = test::short_session("wheels");
  o.can_offset_s = 0.25;
  run_simulation(o);
  // The signals as session.yaml configures them (the robot template's TPDOs).
  std::vector<drivers::can::MessageSpec> messages;
  for (const auto& [id, name] : {std::pair{0x181u, "left"}, std::pair{0x182u, "right"}}) {
    drivers::can::SignalSpec s;
    s.name = name;
    s.length = 32;
    s.is_signed = true;
    drivers::can::add_inline_signal(messages, id, false, s);
  }
  drivers::can::SignalDecoder decoder(messages, {}, false);
  std::vector<double> values(decoder.slot_count());
  drivers::can::CandumpReader reader(o.out / "can.log");
  drivers::can::Frame frame;
  std::vector<double> left, right;
  std::vector<std::int64_t> left_time;
  while (reader.next(frame)) {
    decoder.decode(frame, values);
    if (frame.id == 0x181) {
      left.push_back(values[static_cast<std::size_t>(decoder.slot("left"))]);
      left_time.push_back(frame.time_us);
    } else if (frame.id == 0x182) {
      right.push_back(values[static_cast<std::size_t>(decoder.slot("right"))]);
    }
  }
  EXPECT_EQ(reader.stats().malformed, 0u);
  const auto truth = read_truth(o.out / "truth_wheels.csv");
  ASSERT_EQ(left.size(), truth.size());
  ASSERT_EQ(right.size(), truth.size());
  const double counts_per_rad = 16384 / (2 * std::numbers::pi);
  const double dt = 0.01;
  double fastest = 0;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    // The CAN clock runs the configured offset ahead of the LiDAR's.
    EXPECT_NEAR(static_cast<double>(left_time[k]) * 1e-6 - truth[k].t, o.can_offset_s, 2e-6);
    // Quantisation (±0.5) plus the count noise (σ 0.3): within 2 counts.
    EXPECT_NEAR(left[k], truth[k].left * counts_per_rad, 2.0);
    EXPECT_NEAR(right[k], truth[k].right * counts_per_rad, 2.0);
    if (k == 0) continue;
    // Speeds from successive counts: within (2 + 2) counts per frame interval.
    const double v_true = (truth[k].left - truth[k - 1].left) / dt;
    const double v_can = (left[k] - left[k - 1]) / counts_per_rad / dt;
    EXPECT_NEAR(v_can, v_true, 4.0 / counts_per_rad / dt);
    fastest = std::max(fastest, v_true);
  }
  EXPECT_GT(fastest, 3.0);  // the robot really drove (≥ 0.5 m/s on a 0.165 m wheel)
}

// The accelerometer's frames, decoded with the signals session.yaml gives
// them, read the robot's specific force (sim/imu.hpp) plus a small constant
// bias and noise: gravity's up within 0.1°.
TEST(SimSession, CanLogCarriesTheAccelerometerAsSessionYamlDescribesIt) {
  SimOptions o = test::short_session("imu");
  run_simulation(o);
  const config::Config c = config::load_config(o.out / "session.yaml");
  ASSERT_TRUE(c.imu.enabled);
  std::vector<drivers::can::MessageSpec> messages;
  for (const config::CanSignal& cs : c.can.signals) {
    drivers::can::SignalSpec spec;
    spec.name = cs.name;
    spec.start_bit = static_cast<unsigned>(cs.start_bit);
    spec.length = static_cast<unsigned>(cs.length);
    spec.is_signed = cs.value_type == config::ValueType::signed_int;
    spec.factor = cs.factor;
    drivers::can::add_inline_signal(messages, cs.id, false, spec);
  }
  drivers::can::SignalDecoder decoder(messages, {}, false);
  std::vector<double> values(decoder.slot_count());
  const auto slot = [&](const std::string& name) { return static_cast<std::size_t>(decoder.slot(name)); };
  const BodyTrack path = simulated_path(simulated_scene(o), o);
  drivers::can::CandumpReader reader(o.out / "can.log");
  drivers::can::Frame frame;
  std::size_t readings = 0;
  Eigen::Vector3d sum_error = Eigen::Vector3d::Zero();
  double worst = 0.0;
  while (reader.next(frame)) {
    const drivers::can::DecodeResult r = decoder.decode(frame, values);
    if (r.status != drivers::can::DecodeStatus::decoded || frame.id != 0x190) continue;
    const Eigen::Vector3d f(values[slot(c.imu.accel_x_signal)], values[slot(c.imu.accel_y_signal)],
                            values[slot(c.imu.accel_z_signal)]);
    const double t = 1e-6 * static_cast<double>(frame.time_us) - 1e-9 * static_cast<double>(o.start_time_ns);
    const auto i = static_cast<std::size_t>(std::lround(t * BodyTrack::kRate));
    const Eigen::Vector3d error = f - specific_force_at(path, std::min(i, path.samples().size() - 2));
    sum_error += error;
    worst = std::max(worst, error.cwiseAbs().maxCoeff());
    ++readings;
  }
  EXPECT_EQ(readings, static_cast<std::size_t>(o.duration_s * 100.0) + 1);
  // Bias (σ 9.8 mm/s² per axis) plus noise (σ 4.2) plus quantisation (0.5).
  EXPECT_LT(worst, 4.0 * 0.0098 + 5.0 * 0.0042);
  const Eigen::Vector3d bias = sum_error / static_cast<double>(readings);
  EXPECT_LT(bias.cwiseAbs().maxCoeff(), 4.0 * 0.0098) << bias.transpose();
  // At rest (the first second) the reading is gravity's reaction: up in the body, 9.81 m/s² long.
  const Eigen::Vector3d still = specific_force_at(path, 10);
  EXPECT_NEAR(still.norm(), 9.80665, 1e-6);
  EXPECT_NEAR((path.samples()[10].orientation * still).normalized().z(), 1.0, 1e-12);
}

TEST(SimSession, SessionConfigIsValidAndPointsAtTheFiles) {
  SimOptions o = test::short_session("config");
  run_simulation(o);
  const auto config = config::load_config(o.out / "session.yaml");
  EXPECT_EQ(config.lidar.model, "VLP-16");
  EXPECT_EQ(config.lidar.pcap.empty(), false);
  EXPECT_TRUE(config.can.enabled);
}

void expect_rejected(SimOptions o, const std::string& key) {
  try {
    run_simulation(o);
    ADD_FAILURE() << "accepted bad " << key;
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), key) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(o.out / "lidar.pcap")) << "work started before rejecting " << key;
}

TEST(SimSession, ImpossibleOptionsAreRejectedBeforeAnyWork) {
  SimOptions o = test::short_session("rejected");
  std::filesystem::remove_all(o.out);
  auto bad = o;
  bad.duration_s = -5;
  expect_rejected(bad, "--duration");
  bad = o;
  bad.sensor = "HDL-64E";
  expect_rejected(bad, "--sensor");
  bad = o;
  bad.sensor = "OS1-64";
  bad.rpm = 1200;  // its simulated mode is 1024x10
  expect_rejected(bad, "--rpm");
  bad = o;
  bad.scene = "moon";
  expect_rejected(bad, "--scene");
  bad = o;
  bad.speed_mps = 3.0;
  expect_rejected(bad, "--speed");
  bad = o;
  bad.noise_m = -0.01;
  expect_rejected(bad, "--noise-m");
  bad = o;
  bad.max_range_m = 0.2;
  expect_rejected(bad, "--max-range-m");
  bad = o;
  bad.lateral_offset_m = 3.0;  // into the rock of a 3.5-5 m drift
  expect_rejected(bad, "--lateral-offset-m");
}

}  // namespace
}  // namespace adit::sim
