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
#include "adit/drivers/lidar/ouster_metadata.hpp"
#include "adit/drivers/lidar/ouster_packet.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "adit/sim/imu.hpp"
#include "adit/sim/imu_kinematics.hpp"
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
  EXPECT_EQ(files, 10u);
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
  for (const char* name : {"lidar.pcap", "OS1-64.json", "session.yaml", "can.log", "truth_imu.csv", "truth_ouster_imu.csv"}) {
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

// The CAN signals session.yaml declares, as the daemon's decoder reads them.
drivers::can::SignalDecoder config_decoder(const config::Config& c) {
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
  return drivers::can::SignalDecoder(messages, {}, false);
}

struct BiasRow {
  double t;
  Eigen::Vector3d gyro, accel;
};

std::vector<BiasRow> read_bias_truth(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::vector<BiasRow> rows;
  while (std::getline(in, line)) {
    BiasRow r{};
    if (line.starts_with("#") || line.starts_with("t,")) continue;
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf", &r.t, &r.gyro.x(), &r.gyro.y(), &r.gyro.z(),
                    &r.accel.x(), &r.accel.y(), &r.accel.z()) == 7)
      rows.push_back(r);
  }
  return rows;
}

// The CAN IMU's frames, decoded with the signals session.yaml gives them:
// the samples the model made (sim/imu.hpp) within half a count, each
// gyroscope frame 100 µs after its accelerometer frame, stamped on the CAN
// clock (the configured offset ahead of the truth's: session.yaml's
// time_offset_s says so); minus the true motion and the biases of
// truth_imu.csv, what is left is white noise of the configured density.
struct CanImuCheck {
  std::size_t accel = 0, gyro = 0, other = 0;
};

CanImuCheck check_can_imu(const SimOptions& o) {
  const config::Config c = config::load_config(o.out / "session.yaml");
  EXPECT_TRUE(c.imu.enabled);
  EXPECT_EQ(c.imu.source, config::ImuSource::can);
  EXPECT_EQ(c.imu.gyro_x_signal, "imu_gyro_x");
  EXPECT_NEAR(c.imu.time_offset_s, o.can_offset_s + o.imu_time_offset_s, 1e-12);
  drivers::can::SignalDecoder decoder = config_decoder(c);
  std::vector<double> values(decoder.slot_count());
  const auto slot = [&](const std::string& name) { return static_cast<std::size_t>(decoder.slot(name)); };
  const BodyTrack path = simulated_path(simulated_scene(o), o);
  const ImuOptions imu = simulated_imu(o, SimImuSource::can);
  const std::vector<ImuSample> samples = simulate_imu(path, imu);
  const std::vector<BiasRow> biases = read_bias_truth(o.out / "truth_imu.csv");
  EXPECT_EQ(biases.size(), samples.size());
  drivers::can::CandumpReader reader(o.out / "can.log");
  drivers::can::Frame frame;
  CanImuCheck n;
  std::int64_t accel_time = 0;
  Eigen::Vector3d accel_residual2 = Eigen::Vector3d::Zero();
  const double start = 1e-9 * static_cast<double>(o.start_time_ns);
  while (reader.next(frame)) {
    const drivers::can::DecodeResult r = decoder.decode(frame, values);
    if (r.status != drivers::can::DecodeStatus::decoded || (frame.id != 0x190 && frame.id != 0x191)) {
      ++n.other;
      continue;
    }
    if (frame.id == 0x190) {
      const std::size_t k = n.accel++;
      if (k >= samples.size()) break;
      const Eigen::Vector3d f(values[slot(c.imu.accel_x_signal)], values[slot(c.imu.accel_y_signal)],
                              values[slot(c.imu.accel_z_signal)]);
      EXPECT_LT((f - samples[k].accel).cwiseAbs().maxCoeff(), 0.0005 + 1e-9) << k;
      // Stamped on the CAN clock, 300 µs after the sample.
      EXPECT_NEAR(1e-6 * static_cast<double>(frame.time_us) - start - samples[k].t,
                  c.imu.time_offset_s + 300e-6, 1.5e-6) << k;
      EXPECT_NEAR(biases[k].t - start, samples[k].t, 1e-6);
      const ImuKinematics truth = imu_kinematics(path, samples[k].t, 1.0 / imu.rate_hz, imu.mount, imu.motion);
      accel_residual2 += (f - truth.specific_force - biases[k].accel).cwiseAbs2();
      accel_time = frame.time_us;
    } else {
      const std::size_t k = n.gyro++;
      if (k >= samples.size()) break;
      const Eigen::Vector3d w(values[slot(c.imu.gyro_x_signal)], values[slot(c.imu.gyro_y_signal)],
                              values[slot(c.imu.gyro_z_signal)]);
      EXPECT_LT((w - samples[k].gyro).cwiseAbs().maxCoeff(), 0.0001 + 1e-9) << k;
      EXPECT_EQ(frame.time_us - accel_time, 100) << k;
      EXPECT_EQ(n.gyro, n.accel);
    }
  }
  EXPECT_EQ(n.accel, samples.size());
  EXPECT_EQ(n.gyro, samples.size());
  EXPECT_EQ(samples.size(), static_cast<std::size_t>(o.duration_s * imu.rate_hz) + 1);
  // Noise σ = density·√rate (and quantisation's 0.29 mm/s²).
  const double sigma = o.imu_noise.accel_noise_density * std::sqrt(imu.rate_hz);
  for (int axis = 0; axis < 3; ++axis)
    EXPECT_NEAR(std::sqrt(accel_residual2(axis) / static_cast<double>(n.accel)) / sigma, 1.0, 0.1) << axis;
  return n;
}

TEST(SimSession, RobotCanLogCarriesTheImuAsSessionYamlDescribesIt) {
  SimOptions o = test::short_session("imu");
  run_simulation(o);
  const CanImuCheck n = check_can_imu(o);
  EXPECT_EQ(n.other, 2 * (static_cast<std::size_t>(o.duration_s * 100.0) + 1));  // the wheels' TPDOs
  // At rest (the first second) the robot's accelerometer reads gravity's reaction: up in the body, 9.81 m/s² long.
  const BodyTrack path = simulated_path(simulated_scene(o), o);
  const Eigen::Vector3d still = specific_force_at(path, 10);
  EXPECT_NEAR(still.norm(), 9.80665, 1e-6);
  EXPECT_NEAR((path.samples()[10].orientation * still).normalized().z(), 1.0, 1e-12);
}

// A handheld (and a drone) with a VLP-16: a CAN bus with the IMU alone, no
// wheels; its clock offset reaches session.yaml with the right sign.
TEST(SimSession, HandheldCanLogHasOnlyTheImu) {
  SimOptions o = test::short_session("handheld-can");
  o.platform = "handheld";
  o.scene = "building";
  o.duration_s = 9.0;
  o.can_offset_s = 0.25;
  o.imu_time_offset_s = 0.01;
  o.imu_position_m = Eigen::Vector3d(0.05, -0.02, 0.08);
  run_simulation(o);
  const config::Config c = config::load_config(o.out / "session.yaml");
  EXPECT_TRUE(c.can.enabled);
  EXPECT_FALSE(c.wheel_odometry.enabled);
  EXPECT_EQ(c.imu.position_m[0], 0.05);
  EXPECT_EQ(c.imu.position_m[2], 0.08);
  EXPECT_EQ(c.imu.gyro_noise_density, o.imu_noise.gyro_noise_density);
  EXPECT_EQ(c.imu.accel_bias_walk, o.imu_noise.accel_bias_walk);
  EXPECT_FALSE(std::filesystem::exists(o.out / "truth_wheels.csv"));
  const CanImuCheck n = check_can_imu(o);
  EXPECT_EQ(n.other, 0u);
}

TEST(SimSession, WheelClockOffsetHasTheDaemonsSign) {
  SimOptions o = test::short_session("wheel-offset");
  o.can_offset_s = -0.125;
  run_simulation(o);
  const config::Config c = config::load_config(o.out / "session.yaml");
  // aditd takes frame time − time_offset_s as the LiDAR's time (daemon/src/can_feed.cpp).
  EXPECT_EQ(c.wheel_odometry.time_offset_s, -0.125);
  EXPECT_EQ(c.imu.time_offset_s, -0.125);
}

// An Ouster session: the IMU packets in the pcap (port 7503, 100 Hz, 48
// bytes) decode with the driver's decoder to the samples within the real
// unit's steps, stamped on the sensor clock as the columns are, in capture
// order among the LiDAR packets; session.yaml reads them (source ouster) and
// places the IMU where the metadata's imu_to_sensor_transform does.
TEST(SimSession, OusterImuPacketsDecodeToTheSamplesOnTheSensorClock) {
  SimOptions o = test::short_session("handheld-ouster");
  o.platform = "handheld";
  o.scene = "building";
  o.duration_s = 9.0;
  o.sensor = "OS1-64";
  o.imu_time_offset_s = 0.002;
  run_simulation(o);
  const config::Config c = config::load_config(o.out / "session.yaml");
  ASSERT_TRUE(c.imu.enabled);
  EXPECT_EQ(c.imu.source, config::ImuSource::ouster);
  EXPECT_FALSE(c.can.enabled);
  EXPECT_FALSE(std::filesystem::exists(o.out / "can.log"));
  const Eigen::Isometry3d extrinsics = simulated_extrinsics(o);
  const auto metadata = drivers::load_ouster_metadata(o.out / "OS1-64.json");
  const Eigen::Vector3d imu_in_sensor(metadata.imu_to_sensor[3] * 1e-3, metadata.imu_to_sensor[7] * 1e-3,
                                      metadata.imu_to_sensor[11] * 1e-3);
  const Eigen::Vector3d imu_in_body = extrinsics * imu_in_sensor;
  for (int axis = 0; axis < 3; ++axis)
    EXPECT_NEAR(c.imu.position_m[static_cast<std::size_t>(axis)], imu_in_body(axis), 1e-9);
  EXPECT_EQ(c.imu.time_offset_s, 0.002);

  const BodyTrack path = simulated_path(simulated_scene(o), o);
  const ImuOptions imu = simulated_imu(o, SimImuSource::ouster);
  EXPECT_EQ(imu.rate_hz, 100.0);
  EXPECT_TRUE((imu.mount.translation() - imu_in_body).isZero(1e-12));
  const std::vector<ImuSample> samples = simulate_imu(path, imu);
  EXPECT_EQ(read_bias_truth(o.out / "truth_imu.csv").size(), samples.size());
  drivers::PcapReader reader(o.out / "lidar.pcap");
  drivers::UdpDatagram d;
  std::size_t k = 0, lidar = 0;
  std::int64_t previous_capture = 0;
  const double g_step = 9.80665 / 2048.0, dps_step = std::numbers::pi / 180.0 / 32.768;
  while (reader.next(d)) {
    EXPECT_GE(d.capture_time_ns, previous_capture);  // one capture, in time order
    previous_capture = d.capture_time_ns;
    if (d.dst_port != 7503) {
      ++lidar;
      continue;
    }
    drivers::OusterImuSample decoded;
    ASSERT_TRUE(drivers::decode_ouster_imu(d.payload, decoded));
    ASSERT_LT(k, samples.size());
    const auto stamp = static_cast<std::uint64_t>(o.start_time_ns + std::llround((samples[k].t + 0.002) * 1e9));
    EXPECT_EQ(decoded.system_time_ns, stamp) << k;
    EXPECT_EQ(decoded.accel_time_ns, stamp) << k;
    EXPECT_EQ(decoded.gyro_time_ns, stamp) << k;
    EXPECT_EQ(d.capture_time_ns, static_cast<std::int64_t>(stamp) + 100'000) << k;
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_NEAR(decoded.accel_mps2[axis], samples[k].accel(axis), 0.5 * g_step + 1e-5) << k;
      EXPECT_NEAR(decoded.gyro_radps[axis], samples[k].gyro(axis), 0.5 * dps_step + 1e-6) << k;
    }
    ++k;
  }
  EXPECT_EQ(k, samples.size());
  EXPECT_EQ(k, static_cast<std::size_t>(o.duration_s * 100.0) + 1);
  EXPECT_GT(lidar, static_cast<std::size_t>(o.duration_s * 600.0));
  // At the start the walker stands still: the decoded accelerometer reads about 1 g.
  drivers::PcapReader again(o.out / "lidar.pcap");
  while (again.next(d) && d.dst_port != 7503) {}
  drivers::OusterImuSample first;
  ASSERT_TRUE(drivers::decode_ouster_imu(d.payload, first));
  EXPECT_NEAR(std::hypot(first.accel_mps2[0], first.accel_mps2[1], first.accel_mps2[2]), 9.80665, 0.2);
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
  bad = o;
  bad.platform = "boat";
  expect_rejected(bad, "--platform");
  bad = o;
  bad.platform = "handheld";
  bad.speed_mps = 1.8;  // a run, not a walk
  expect_rejected(bad, "--speed");
  bad = o;
  bad.imu_rate_hz = 50.0;
  expect_rejected(bad, "--imu-rate-hz");
  bad = o;
  bad.imu_noise.accel_bias_walk = -1e-3;
  expect_rejected(bad, "--accel-bias-walk");
  bad = o;
  bad.vibration = "sometimes";
  expect_rejected(bad, "--vibration");
  bad = o;
  bad.platform = "drone";
  bad.duration_s = 30.0;
  bad.sensor = "OS1-64";
  bad.imu_position_m = Eigen::Vector3d(0.1, 0.0, 0.0);  // the Ouster's IMU is inside the sensor
  expect_rejected(bad, "--imu-position-m");
  bad.sensor = "Mid-360";  // so is the Mid-360's
  expect_rejected(bad, "--imu-position-m");
  bad.imu_position_m.setZero();
  bad.imu_rate_hz = 100.0;  // it sends 200 Hz
  expect_rejected(bad, "--imu-rate-hz");
}

}  // namespace
}  // namespace adit::sim
