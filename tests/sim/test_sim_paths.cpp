// The platforms move as the issue asks: the robot within 1.5 m/s with a
// bumpy ride, the drone within 2 m/s and 90°/s of yaw, hovering and climbing,
// the walker at a walking pace with its step bob and turns to 120°/s; all end
// near where they started and stay inside the scene.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "adit/sim/handheld_path.hpp"
#include "adit/sim/route_schedule.hpp"
#include "adit/sim/session.hpp"

namespace adit::sim {
namespace {

struct Motion {
  double top_speed = 0, top_yaw_rate = 0, top_tilt = 0, min_z = 1e9, max_z = -1e9, closest_wall = -1e9, length = 0;
  // How fast the body tilts (the angle its up axis turns through over 50 ms, per second):
  // anywhere, and while it turns on the spot (slower than 5 cm/s, faster than 0.3 rad/s of yaw).
  double top_tilt_rate = 0, top_tilt_rate_turning_on_spot = 0;
  // The body's velocity across its heading (levelled), over 50 ms, and how far it
  // moved across its heading in any one second: a wheeled robot's are nil.
  double top_sideways_speed = 0, top_sideways_slide_1s = 0;
  // The change of the 50 ms yaw rate over 50 ms: a body with mass turns smoothly.
  double top_yaw_acceleration = 0;
  Eigen::Vector3d start, end;
};

Motion measure(const SimOptions& o) {
  const Scene scene = simulated_scene(o);
  const BodyTrack path = simulated_path(scene, o);
  const auto& s = path.samples();
  Motion m;
  m.start = s.front().position;
  m.end = s.back().position;
  const double dt = 1.0 / BodyTrack::kRate;
  std::vector<double> yaw_rate_50ms(s.size(), 0.0);
  std::vector<double> sideways(s.size(), 0.0);  // each step's move across the body's heading
  double slide = 0.0;                           // summed over the last second
  constexpr auto second = static_cast<std::size_t>(BodyTrack::kRate);
  for (std::size_t i = 1; i < s.size(); ++i) {
    const Eigen::Vector3d step = s[i].position - s[i - 1].position;
    const Eigen::Vector3d forward = s[i - 1].orientation * Eigen::Vector3d::UnitX();
    sideways[i] = step.dot(Eigen::Vector3d(-forward.y(), forward.x(), 0.0).normalized());
    slide += sideways[i] - (i >= second ? sideways[i - second] : 0.0);
    m.top_sideways_slide_1s = std::max(m.top_sideways_slide_1s, std::abs(slide));
    m.length += step.norm();
    // Velocity over 50 ms (the samples' linear interpolation makes 5 ms steps noisy in angle only).
    if (i >= 10) m.top_speed = std::max(m.top_speed, (s[i].position - s[i - 10].position).norm() / (10 * dt));
    const Eigen::Vector3d f0 = s[i - 1].orientation * Eigen::Vector3d::UnitX();
    const Eigen::Vector3d f1 = s[i].orientation * Eigen::Vector3d::UnitX();
    const double dyaw = std::remainder(std::atan2(f1.y(), f1.x()) - std::atan2(f0.y(), f0.x()), 2 * std::numbers::pi);
    m.top_yaw_rate = std::max(m.top_yaw_rate, std::abs(dyaw) / dt);
    if (i >= 10) {
      const Eigen::Vector3d up0 = s[i - 10].orientation * Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d up1 = s[i].orientation * Eigen::Vector3d::UnitZ();
      const double rate = std::atan2(up0.cross(up1).norm(), up0.dot(up1)) / (10 * dt);
      m.top_tilt_rate = std::max(m.top_tilt_rate, rate);
      const double speed = (s[i].position - s[i - 10].position).norm() / (10 * dt);
      const Eigen::Vector3d mid = s[i - 5].orientation * Eigen::Vector3d::UnitX();
      const Eigen::Vector3d left = Eigen::Vector3d(-mid.y(), mid.x(), 0.0).normalized();
      m.top_sideways_speed = std::max(m.top_sideways_speed, std::abs((s[i].position - s[i - 10].position).dot(left)) / (10 * dt));
      const Eigen::Vector3d back = s[i - 10].orientation * Eigen::Vector3d::UnitX();
      const Eigen::Vector3d now = s[i].orientation * Eigen::Vector3d::UnitX();
      yaw_rate_50ms[i] = std::remainder(std::atan2(now.y(), now.x()) - std::atan2(back.y(), back.x()), 2 * std::numbers::pi) / (10 * dt);
      if (i >= 20)
        m.top_yaw_acceleration = std::max(m.top_yaw_acceleration, std::abs(yaw_rate_50ms[i] - yaw_rate_50ms[i - 10]) / (10 * dt));
      if (speed < 0.05 && std::abs(dyaw) / dt > 0.3)
        m.top_tilt_rate_turning_on_spot = std::max(m.top_tilt_rate_turning_on_spot, rate);
    }
    const Eigen::Vector3d up = s[i].orientation * Eigen::Vector3d::UnitZ();
    m.top_tilt = std::max(m.top_tilt, std::acos(std::clamp(up.z(), -1.0, 1.0)));
    m.min_z = std::min(m.min_z, s[i].position.z());
    m.max_z = std::max(m.max_z, s[i].position.z());
    m.closest_wall = std::max(m.closest_wall, scene.plan.distance(s[i].position.head<2>()));
  }
  return m;
}

constexpr double kDeg = std::numbers::pi / 180.0;

TEST(SimPaths, RobotDrivesOutAndBackWithinItsLimits) {
  SimOptions o;
  o.duration_s = 60;
  o.speed_mps = 1.5;
  const Motion m = measure(o);
  EXPECT_LE(m.top_speed, 1.5 * 1.02);
  EXPECT_GT(m.top_speed, 1.3);
  EXPECT_GT(m.top_tilt, 0.3 * kDeg);  // bumps roll and pitch the body
  EXPECT_LT(m.top_tilt, 3.0 * kDeg);
  // The floor tilts the body as fast as the wheels roll over it: at 1.5 m/s
  // over ~1 m bumps a few °/s, turning on the spot (the wheels roll 0.17 m/s)
  // well under 1 °/s. The bumps once followed the route distance plus 1000 m
  // per turn, and the body shook by ±1° some 200 times a second while it
  // turned: 37 °/s over 50 ms.
  EXPECT_GT(m.top_tilt_rate_turning_on_spot, 0.0);  // it did turn on the spot
  EXPECT_LT(m.top_tilt_rate_turning_on_spot, 1.0 * kDeg);
  EXPECT_LT(m.top_tilt_rate, 10.0 * kDeg);
  EXPECT_LT((m.end - m.start).head<2>().norm(), 0.05);  // back where it started
  EXPECT_GT(m.length, 60.0);
  EXPECT_LT(m.closest_wall, -0.4);
}

// Wheels roll, they do not slide: the body points along the path it drives,
// in the curves and at a closed route's start too, and turns smoothly
// (decision 078: its heading was smoothed over a metre and its position not,
// a slide of up to 39 mm in a second that no wheel measured; a heading from
// the route's 5 cm steps instead turned it at up to 17 rad/s²).
TEST(SimPaths, RobotNeverSlidesSideways) {
  for (const char* scene : {"mine", "building", "drift"}) {
    SimOptions o;
    o.scene = scene;
    o.duration_s = 60;
    const Motion m = measure(o);
    EXPECT_GT(m.length, 30.0) << scene;
    EXPECT_LT(m.top_sideways_speed, 0.005) << scene;
    EXPECT_LT(m.top_sideways_slide_1s, 0.002) << scene;
    EXPECT_LT(m.top_yaw_acceleration, 3.0) << scene;
  }
}

// On a loop, a point a hair before the start is the start: fmod of a tiny
// negative distance plus the loop's length rounds to the length itself, and
// once indexed one past the last point (a robot sample 0.4 m off, facing back).
TEST(SimPaths, AJustNegativeDistanceOnALoopIsItsStart) {
  Route loop;
  loop.closed = true;
  for (int i = 0; i < 100; ++i) {
    const double a = 2.0 * std::numbers::pi * i / 100.0;
    loop.points.emplace_back(std::cos(a), std::sin(a));
  }
  loop.step = (loop.points[1] - loop.points[0]).norm();
  for (const double s : {-1e-18, -1e-17, -0.0, 0.0}) {
    const RoutePoint p = route_at(loop, s);
    EXPECT_LT((p.position - loop.points[0]).norm(), 1e-12) << s;
  }
  EXPECT_LT((route_at(loop, -0.5 * loop.step).position - 0.5 * (loop.points[0] + loop.points[99])).norm(), 1e-9);
}

TEST(SimPaths, RobotDrivesWholeLapsWhenThereIsTime) {
  SimOptions o;
  o.duration_s = 300;
  o.speed_mps = 1.5;
  const Motion m = measure(o);
  const double loop = simulated_scene(o).route.length();
  EXPECT_GT(loop, 100.0);
  EXPECT_LT(loop, 500.0);
  EXPECT_NEAR(m.length, loop * std::floor(1.5 * 299 / loop), 0.02 * loop);
  EXPECT_LT((m.end - m.start).head<2>().norm(), 0.3);
}

TEST(SimPaths, DroneHoversClimbsAndTurnsWithinItsLimits) {
  for (const double duration : {40.0, 400.0}) {  // out and back; whole laps
    SimOptions o;
    o.platform = "drone";
    o.duration_s = duration;
    o.speed_mps = 2.0;
    const Motion m = measure(o);
    EXPECT_LE(m.top_speed, 2.0 * 1.05) << duration;
    if (duration < 100) {
      EXPECT_GT(m.top_speed, 1.8);  // laps: slower, to end where it started
    }
    EXPECT_LE(m.top_yaw_rate, 90.0 * kDeg) << duration;
    EXPECT_GT(m.top_yaw_rate, 20.0 * kDeg) << duration;
    EXPECT_LT(m.min_z, 0.4) << duration;  // took off from the floor
    EXPECT_GT(m.max_z, 2.3) << duration;  // and rose and sank in flight
    EXPECT_GT(m.top_tilt, 1.0 * kDeg) << duration;
    EXPECT_LT(m.top_tilt, 15.0 * kDeg) << duration;
    EXPECT_LT((m.end - m.start).head<2>().norm(), 0.5) << duration;
    EXPECT_LT(m.closest_wall, -0.4) << duration;
  }
  // Hovering: still between the climb and moving off.
  SimOptions o;
  o.platform = "drone";
  o.duration_s = 40;
  const Scene scene = simulated_scene(o);
  const BodyTrack path = simulated_path(scene, o);
  EXPECT_LT((path.pose(5.9).translation() - path.pose(4.1).translation()).norm(), 1e-3);
  // --ground-s: on its legs (0.3 m, level, no turbulence) for that long, then the same climb.
  o.ground_s = 2.0;
  const BodyTrack grounded = simulated_path(scene, o);
  for (const double t : {0.0, 1.0, 1.99}) {
    EXPECT_NEAR(grounded.pose(t).translation().z(), 0.3, 1e-9) << t;
    EXPECT_TRUE(grounded.pose(t).linear().isApprox(grounded.pose(0.0).linear(), 1e-12)) << t;
  }
  EXPECT_GT(grounded.pose(2.0 + 4.0).translation().z(), 1.4);
  EXPECT_LT((grounded.pose(7.9).translation() - grounded.pose(6.1).translation()).norm(), 1e-3);
}

// The walker, in the mine and the building, out and back and in laps: a
// walking pace, the sensor about 1.5 m up, the hand bobbing ±2-3 cm once per
// step at about 2 Hz, a few degrees of sway, glances and turns that reach but
// never exceed 120°/s of yaw; deterministic from the seed.
TEST(SimPaths, HandheldWalksBobsAndTurnsWithinItsLimits) {
  for (const char* scene : {"mine", "building"}) {
    for (const double duration : {40.0, 240.0}) {
      SimOptions o;
      o.platform = "handheld";
      o.scene = scene;
      o.duration_s = duration;
      o.seed = 4;
      const Motion m = measure(o);
      const std::string what = std::string(scene) + " " + std::to_string(duration);
      EXPECT_LE(m.top_speed, 1.5) << what;
      EXPECT_GT(m.top_speed, 1.2) << what;
      EXPECT_LE(m.top_yaw_rate, 120.0 * kDeg + 1e-9) << what;
      EXPECT_GT(m.top_yaw_rate, 119.0 * kDeg) << what;  // the glances reach the limit
      EXPECT_GT(m.min_z + 0.10, 1.45) << what;          // the sensor 0.10 m above the hand
      EXPECT_LT(m.max_z + 0.10, 1.55) << what;
      EXPECT_GT(m.top_tilt, 2.0 * kDeg) << what;
      EXPECT_LT(m.top_tilt, 8.0 * kDeg) << what;
      EXPECT_LT((m.end - m.start).head<2>().norm(), 0.5) << what;
      EXPECT_LT(m.closest_wall, -0.4) << what;
    }
  }
  // The bob while cruising (10-20 s of a 40 s walk): its height swings
  // 4-6 cm peak to peak and crosses its mean about 2 × 1.9 times a second.
  SimOptions o;
  o.platform = "handheld";
  o.duration_s = 40.0;
  const BodyTrack path = simulated_path(simulated_scene(o), o);
  double low = 1e9, high = -1e9, mean = 0.0;
  const std::size_t a = 10 * 200, b = 20 * 200;
  for (std::size_t i = a; i < b; ++i) {
    const double z = path.samples()[i].position.z();
    low = std::min(low, z);
    high = std::max(high, z);
    mean += z / static_cast<double>(b - a);
  }
  int crossings = 0;
  for (std::size_t i = a + 1; i < b; ++i)
    crossings += (path.samples()[i].position.z() - mean) * (path.samples()[i - 1].position.z() - mean) < 0 ? 1 : 0;
  EXPECT_GT(high - low, 0.04);
  EXPECT_LT(high - low, 0.06);
  EXPECT_NEAR(crossings / 10.0 / 2.0, 1.9, 0.2);
  // Standing still for the first two seconds (the hand drifts under 1°/s).
  EXPECT_LT((path.pose(1.9).translation() - path.pose(0.0).translation()).norm(), 1e-9);
  // Same seed, same walk; another seed, another.
  const BodyTrack again = simulated_path(simulated_scene(o), o);
  for (std::size_t i = 0; i < path.samples().size(); i += 97)
    ASSERT_TRUE(path.samples()[i].position == again.samples()[i].position &&
                path.samples()[i].orientation.coeffs() == again.samples()[i].orientation.coeffs());
  o.seed = 9;
  EXPECT_NE(simulated_path(simulated_scene(o), o).samples()[3000].orientation.coeffs(),
            path.samples()[3000].orientation.coeffs());
}

}  // namespace
}  // namespace adit::sim
