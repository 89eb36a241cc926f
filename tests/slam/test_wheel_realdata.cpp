// Wheel odometry on the RAV4 drive against its GNSS/INS pose track.

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "adit/drivers/can/candump.hpp"
#include "adit/drivers/can/dbc.hpp"
#include "adit/drivers/can/decoder.hpp"
#include "adit/eval/wheel_calibration.hpp"
#include "adit/slam/wheel_odometry.hpp"
#include "shared_data.hpp"

namespace can = adit::drivers::can;
namespace slam = adit::slam;
namespace eval = adit::eval;

namespace {

struct Drive {
  std::vector<eval::WheelSpeedSample> rear;  // rear wheels: not steered, a differential pair
  std::vector<eval::PlanarPosition> reference;
  double length_3d = 0.0;  // the pose track's path length including height
};

Drive load(const std::filesystem::path& dir) {
  Drive d;
  const can::Database db = can::load_dbc(dir / "toyota_rav4_2017.dbc");
  const std::vector<std::string> wanted{"WHEEL_SPEED_RL", "WHEEL_SPEED_RR"};
  can::SignalDecoder decoder(db.messages, wanted);
  std::vector<double> v(decoder.slot_count());
  const int rl = decoder.slot("WHEEL_SPEED_RL");
  const int rr = decoder.slot("WHEEL_SPEED_RR");
  can::CandumpReader reader(dir / "drive.candump.log");
  can::Frame f;
  while (reader.next(f))
    if (f.interface_name() == "can0" && decoder.decode(f, v).status == can::DecodeStatus::decoded)
      d.rear.push_back({static_cast<double>(f.time_us) * 1e-6, v[rl], v[rr]});
  std::ifstream in(dir / "reference-pose-track-enu.csv");
  std::string line;
  double previous_up = 0.0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 't') continue;
    eval::PlanarPosition p;
    char comma = 0;
    std::istringstream s(line);
    double up = 0.0;
    s >> p.t >> comma >> p.x >> comma >> p.y >> comma >> up;
    if (!d.reference.empty())
      d.length_3d += std::hypot(p.x - d.reference.back().x, p.y - d.reference.back().y, up - previous_up);
    previous_up = up;
    d.reference.push_back(p);
  }
  return d;
}

}  // namespace

TEST(Rav4Odometry, IntegratedDistanceWithinOnePercentOfThePoseTrack) {
  ADIT_REQUIRE_SHARED_DATA(dir, "can/toyota-rav4-2017");
  const Drive d = load(dir);
  ASSERT_EQ(d.rear.size(), 4974U);
  ASSERT_GT(d.reference.size(), 1000U);
  slam::WheelGeometry g;
  g.track_width = 1.6;
  slam::WheelLimits car;  // a car, not a mine robot: up to 50 m/s, braking/accelerating 10 m/s^2 plus speed noise
  car.max_speed = 50.0;
  car.max_acceleration = 10.0;
  car.speed_noise = 1.0;  // ABS wheel speeds of this car jump by up to 0.96 m/s between 12 ms samples
  slam::WheelOdometry odo(g, {}, car);
  for (const auto& s : d.rear) odo.add_speeds(s.t, s.left, s.right);
  const double planar = eval::path_length(d.reference, d.reference.front().t, d.reference.back().t);
  fmt::print("wheel distance {:.1f} m, pose track {:.1f} m (planar {:.1f} m), ratio {:.4f}; flagged: slip {}\n",
             odo.distance(), d.length_3d, planar, odo.distance() / d.length_3d, odo.stats().slips);
  EXPECT_NEAR(d.length_3d, 1011.8, 0.1);  // the README's figure
  EXPECT_NEAR(odo.distance() / d.length_3d, 1.0, 0.01);
  EXPECT_NEAR(odo.distance() / planar, 1.0, 0.01);
  EXPECT_EQ(odo.stats().gaps + odo.stats().impossible + odo.stats().slips, 0U);
  EXPECT_GT(odo.covariance()(0, 0) + odo.covariance()(1, 1), 0.0);
}

TEST(Rav4Odometry, CalibrationFitsRearTrackAndReducesEndpointError) {
  ADIT_REQUIRE_SHARED_DATA(dir, "can/toyota-rav4-2017");
  const Drive d = load(dir);
  eval::CalibrationOptions o;
  o.nominal.track_width = 1.6;
  const eval::CalibrationResult r = eval::calibrate_wheels(d.rear, d.reference, o);
  fmt::print("scales {:.5f} {:.5f} track {:.4f} m offset {:.3f} s; endpoint {:.2f} -> {:.2f} m; "
             "rms heading {:.4f} -> {:.4f} rad, distance {:.3f} -> {:.3f} m over {} windows\n",
             r.left_scale, r.right_scale, r.effective_track, r.time_offset, r.endpoint_error_before,
             r.endpoint_error_after, r.rms_heading_before, r.rms_heading_after, r.rms_distance_before,
             r.rms_distance_after, r.windows);
  fmt::print("sigma: scales {:.5f} {:.5f} track {:.3f} m offset {:.4f} s\n", r.standard_deviation[0], r.standard_deviation[1], r.standard_deviation[2], r.standard_deviation[3]);
  EXPECT_TRUE(r.converged);
  // This drive is nearly straight (net heading change about 0.002 rad), so
  // the track is only weakly observable: require a usable uncertainty and a
  // fit consistent, within 3 sigma, with the RAV4's geometric rear track (~1.6 m).
  EXPECT_GT(r.standard_deviation[2], 0.0);
  EXPECT_LT(r.standard_deviation[2], 0.5);
  EXPECT_LT(std::abs(r.effective_track - 1.6), 3 * r.standard_deviation[2]);
  EXPECT_LT(r.endpoint_error_after, r.endpoint_error_before);
  EXPECT_LT(r.rms_heading_after, r.rms_heading_before);
}
