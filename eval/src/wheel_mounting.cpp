// The LiDAR's mounting on a wheeled robot from a drive (wheel_mounting.hpp).

#include "adit/eval/wheel_mounting.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>

#include "adit/slam/roll_pitch_yaw.hpp"
#include "adit/slam/trajectory_interpolate.hpp"

namespace adit::eval {
namespace {

// What one window says.
struct Window {
  Eigen::Vector3d sensor_rotation = Eigen::Vector3d::Zero();     // log(R_S,rel), rad, in the sensor's axes
  Eigen::Vector3d sensor_translation = Eigen::Vector3d::Zero();  // t_S,rel, m, in the sensor's axes at the start
  double body_turn = 0.0;                                        // theta_B, rad
  Eigen::Vector2d body_translation = Eigen::Vector2d::Zero();    // t_B,rel, m, in the body's axes at the start
};

constexpr std::size_t kMinWindows = 6;
constexpr std::size_t kMinObserving = 3;  // turning (lever arm) or straight (yaw) windows

// SO(3) logarithm and exponential as rotation vectors (turns below pi).
Eigen::Vector3d log_so3(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}
Eigen::Matrix3d exp_so3(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  return angle < 1e-12 ? Eigen::Matrix3d::Identity() : Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

Eigen::Matrix2d rot2(double a) {
  Eigen::Matrix2d r;
  r << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  return r;
}

// The body's planar pose at t; nullopt outside or across a gap in the wheels.
std::optional<slam::Pose2> body_at(std::span<const slam::WheelSample> w, double t) {
  if (w.empty() || t < w.front().t || t > w.back().t) return std::nullopt;
  const auto it = std::lower_bound(w.begin(), w.end(), t, [](const slam::WheelSample& p, double v) { return p.t < v; });
  if (it == w.begin()) return it->pose;
  if (it->after_gap) return std::nullopt;
  const slam::Pose2& a = (it - 1)->pose;
  const slam::Pose2& b = it->pose;
  const double f = (t - (it - 1)->t) / (it->t - (it - 1)->t);
  return slam::Pose2{a.x + f * (b.x - a.x), a.y + f * (b.y - a.y),
                     slam::wrap_angle(a.theta + f * slam::wrap_angle(b.theta - a.theta))};
}

bool gap_within(std::span<const slam::WheelSample> w, double t0, double t1) {
  const auto first = std::upper_bound(w.begin(), w.end(), t0, [](double v, const slam::WheelSample& p) { return v < p.t; });
  for (auto it = first; it != w.end() && it->t <= t1; ++it)
    if (it->after_gap) return true;
  return false;
}

std::vector<Window> windows_of(const slam::Trajectory& sensor, std::span<const slam::WheelSample> wheels,
                               const MountingOptions& o) {
  std::vector<Window> out;
  if (sensor.empty() || wheels.empty()) return out;
  const double start = std::max(sensor.stamps.front(), wheels.front().t);
  const double end = std::min(sensor.stamps.back(), wheels.back().t);
  for (double t0 = start; t0 + o.window <= end; t0 += o.window) {
    const double t1 = t0 + o.window;
    const auto s0 = slam::interpolate_pose(sensor, t0), s1 = slam::interpolate_pose(sensor, t1);
    const auto b0 = body_at(wheels, t0), b1 = body_at(wheels, t1);
    if (!s0 || !s1 || !b0 || !b1 || gap_within(wheels, t0, t1)) continue;
    Window w;
    const Eigen::Isometry3d rel = s0->inverse() * *s1;
    w.sensor_rotation = log_so3(rel.linear());
    w.sensor_translation = rel.translation();
    w.body_turn = slam::wrap_angle(b1->theta - b0->theta);
    w.body_translation = rot2(-b0->theta) * Eigen::Vector2d(b1->x - b0->x, b1->y - b0->y);
    if (w.body_translation.norm() < o.min_travel && std::abs(w.body_turn) < o.min_turn_for_arm) continue;  // standing
    out.push_back(w);
  }
  return out;
}

// Spans for step 1: from each window's start to where the sensor has turned
// by axis_turn (within axis_span): a bump tilts the body by the same degree
// over any span, so the longer turn sees the axis through it far better
// than one window's.
std::vector<Window> turn_spans(const slam::Trajectory& sensor, std::span<const slam::WheelSample> wheels,
                               const MountingOptions& o) {
  std::vector<Window> out;
  if (sensor.empty() || wheels.empty()) return out;
  std::size_t i = 0, last_end = 0;
  const std::vector<double>& t = sensor.stamps;
  for (double t0 = std::max(t.front(), wheels.front().t); i < sensor.size(); t0 += o.window) {
    while (i < sensor.size() && t[i] < t0) ++i;
    if (i >= sensor.size()) break;
    const auto b0 = body_at(wheels, t[i]);
    if (!b0) continue;
    for (std::size_t j = i + 1; j < sensor.size() && t[j] <= t[i] + o.axis_span; ++j) {
      const Eigen::Matrix3d rel = sensor.poses[i].linear().transpose() * sensor.poses[j].linear();
      if (Eigen::AngleAxisd(rel).angle() < o.axis_turn) continue;
      const auto b1 = body_at(wheels, t[j]);
      // Each end once: spans sharing one are one turn (and one bump), not several.
      if (b1 && j != last_end && !gap_within(wheels, t[i], t[j])) {
        last_end = j;
        Window w;
        w.sensor_rotation = log_so3(rel);
        w.body_turn = slam::wrap_angle(b1->theta - b0->theta);
        out.push_back(w);
      }
      break;
    }
  }
  return out;
}

// Step 1: the sensor's turns are about u: the principal axis of its rotation
// vectors (the top eigenvector of sum w w^T, each weighted by its angle
// squared), whichever way the wheels turned it; only the sign comes from the
// wheels, so a slipping wheel cannot tilt it.
struct AxisFit {
  Eigen::Vector3d u = Eigen::Vector3d::UnitZ();
  double turn_squared = 0.0;  // sum |w|^2, rad^2
};

AxisFit fit_axis(const std::vector<Window>& ws, const std::vector<double>& weight) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  AxisFit f;
  for (std::size_t i = 0; i < ws.size(); ++i) {
    m += weight[i] * ws[i].sensor_rotation * ws[i].sensor_rotation.transpose();
    f.turn_squared += weight[i] * ws[i].sensor_rotation.squaredNorm();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(m);
  f.u = eigen.eigenvectors().col(2);
  double agreement = 0.0;
  for (std::size_t i = 0; i < ws.size(); ++i) agreement += weight[i] * ws[i].body_turn * ws[i].sensor_rotation.dot(f.u);
  if (agreement < 0.0) f.u = -f.u;
  return f;
}

// The sensor's rotation across u: what the planar model cannot explain.
double across(const Window& w, const Eigen::Vector3d& u) {
  const Eigen::Vector3d& r = w.sensor_rotation;
  return (r - r.dot(u) * u).norm();
}

// R_level = Ry(pitch) Rx(roll) with R_level u = e_z: u = R_level^T e_z =
// (-sin p, cos p sin r, cos p cos r).
Eigen::Matrix3d levelling(const Eigen::Vector3d& u) {
  const double pitch = -std::asin(std::clamp(u.x(), -1.0, 1.0));
  const double roll = std::atan2(u.y(), u.z());
  return slam::rotation_from_rpy(Eigen::Vector3d(roll, pitch, 0.0));
}

// One window in the levelled sensor's plane: its turn and its translation.
struct Planar {
  double turn = 0.0;
  Eigen::Vector2d sensor;  // t'
  Eigen::Vector2d body;    // t_B
};

Eigen::Vector2d planar_residual(const Planar& p, const Eigen::Vector3d& x) {
  const Eigen::Vector2d arm = x.head<2>();
  return p.body + rot2(p.turn) * arm - arm - rot2(x.z()) * p.sensor;
}

struct ArmFit {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();  // l_x, l_y, phi
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();  // sum w J^T J
};

// Step 2: the linear solution in (l, cos phi, sin phi), then Gauss-Newton,
// each window weighted.
ArmFit fit_arm(const std::vector<Planar>& ps, const std::vector<double>& weight) {
  Eigen::MatrixXd a(2 * ps.size(), 4);
  Eigen::VectorXd b(2 * ps.size());
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const Planar& p = ps[i];
    const double w = std::sqrt(weight[i]);
    Eigen::Matrix2d m;
    m << p.sensor.x(), -p.sensor.y(), p.sensor.y(), p.sensor.x();
    const auto row = 2 * static_cast<Eigen::Index>(i);
    a.block<2, 2>(row, 0) = w * (rot2(p.turn) - Eigen::Matrix2d::Identity());
    a.block<2, 2>(row, 2) = -w * m;
    b.segment<2>(row) = -w * p.body;
  }
  const Eigen::Vector4d z = a.colPivHouseholderQr().solve(b);
  ArmFit f;
  f.x << z[0], z[1], std::atan2(z[3], z[2]);
  for (int iteration = 0; iteration < 20; ++iteration) {
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    Eigen::Matrix2d d_rot;
    d_rot << -std::sin(f.x.z()), -std::cos(f.x.z()), std::cos(f.x.z()), -std::sin(f.x.z());
    for (std::size_t i = 0; i < ps.size(); ++i) {
      Eigen::Matrix<double, 2, 3> j;
      j.leftCols<2>() = rot2(ps[i].turn) - Eigen::Matrix2d::Identity();
      j.col(2) = -d_rot * ps[i].sensor;
      h += weight[i] * j.transpose() * j;
      g += weight[i] * j.transpose() * planar_residual(ps[i], f.x);
    }
    f.information = h;
    const Eigen::Vector3d step = h.ldlt().solve(-g);
    if (!step.allFinite()) break;
    f.x += step;
    f.x.z() = slam::wrap_angle(f.x.z());
    if (step.norm() < 1e-10) break;
  }
  return f;
}

// 1.4826 * the median absolute value: sigma for Gaussian residuals, robust to outliers.
double robust_sigma(const std::vector<double>& values) {
  std::vector<double> v(values.size());
  std::transform(values.begin(), values.end(), v.begin(), [](double x) { return std::abs(x); });
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return 1.4826 * *mid;
}

std::vector<Planar> planar_windows(const std::vector<Window>& ws, const Eigen::Matrix3d& level) {
  std::vector<Planar> out;
  out.reserve(ws.size());
  for (const Window& w : ws) {
    const Eigen::Matrix3d r = level * exp_so3(w.sensor_rotation) * level.transpose();
    out.push_back({std::atan2(r(1, 0), r(0, 0)), (level * w.sensor_translation).head<2>(), w.body_translation});
  }
  return out;
}

constexpr double kMinTurnSquared = 0.25;  // rad^2: half a radian of turning in one window, or its equal

}  // namespace

MountingResult calibrate_mounting(const slam::Trajectory& sensor, std::span<const slam::WheelSample> wheels,
                                  const MountingOptions& o, const std::optional<GroundSummary>& ground) {
  const std::vector<Window> ws = windows_of(sensor, wheels, o);
  if (ws.size() < kMinWindows)
    throw std::invalid_argument("the LiDAR poses and the wheels overlap in " + std::to_string(ws.size()) +
                                " moving windows; at least " + std::to_string(kMinWindows) + " are needed");
  const std::size_t n = ws.size();
  std::vector<double> weight(n, 1.0);
  if (fit_axis(ws, weight).turn_squared < kMinTurnSquared)
    throw std::invalid_argument("the drive never turns (the sensor turns less than 0.5 rad in all): the body's "
                                "vertical axis cannot be seen from the sensor");

  // Step 1 on the long turns (or, with fewer than kMinObserving, the
  // windows); spans whose rotation leaves the plane (a bump, a ramp) by more
  // than outlier_sigmas of the median are dropped and u fitted again.
  const std::vector<Window> spans = turn_spans(sensor, wheels, o);
  const std::vector<Window>& axis_source = spans.size() >= kMinObserving ? spans : ws;
  std::vector<double> axis_weight(axis_source.size(), 1.0);
  AxisFit axis = fit_axis(axis_source, axis_weight);
  {
    std::vector<double> off(axis_source.size());
    for (std::size_t i = 0; i < off.size(); ++i) off[i] = across(axis_source[i], axis.u);
    const double limit = o.outlier_sigmas * robust_sigma(off);
    for (std::size_t i = 0; i < off.size(); ++i) axis_weight[i] = off[i] <= limit ? 1.0 : 0.0;
    const AxisFit refit = fit_axis(axis_source, axis_weight);
    if (refit.turn_squared >= kMinTurnSquared) axis = refit;
  }
  const Eigen::Vector3d turn_axis = axis.u;
  if (ground) axis.u = ground->normal;
  // The windows for step 2: those off the plane or where the wheels turned
  // otherwise than the sensor (a slip, slip_turn_fraction) are left out.
  std::vector<double> off_axis(n);
  for (std::size_t i = 0; i < n; ++i) off_axis[i] = across(ws[i], axis.u);
  const double axis_limit = o.outlier_sigmas * robust_sigma(off_axis);
  for (std::size_t i = 0; i < n; ++i) {
    const double sensor_turn = ws[i].sensor_rotation.dot(axis.u);
    const double turn_limit = std::max(o.slip_turn_fraction * std::abs(sensor_turn), o.slip_turn_min);
    weight[i] = off_axis[i] <= axis_limit && std::abs(ws[i].body_turn - sensor_turn) <= turn_limit ? 1.0 : 0.0;
  }
  std::size_t kept = 0;
  for (const double w : weight) kept += w > 0.0 ? 1 : 0;
  if (kept < kMinWindows) std::fill(weight.begin(), weight.end(), 1.0);
  const Eigen::Matrix3d level = levelling(axis.u);
  const std::vector<Planar> planar = planar_windows(ws, level);

  // Step 2 by iteratively reweighted least squares with Cauchy's kernel
  // (c = 2.3849 sigma, 95 % efficiency; Zhang, "Parameter estimation
  // techniques", IVC 1997, §5), a window the wheels slipped in weighing
  // little. Sigma is the median's, taken apart for turning and straight
  // windows: wheels are worse in turns (the tyres scrub sideways), and
  // judged by the straight windows every turn, the only windows that show
  // the lever arm, would look wrong.
  const std::vector<double> step1 = weight;
  std::vector<bool> turning(n);
  for (std::size_t i = 0; i < n; ++i) turning[i] = std::abs(planar[i].turn) >= o.min_turn_for_arm;
  ArmFit arm = fit_arm(planar, weight);
  std::vector<double> residual(n), sigma(n);
  const auto judge = [&] {
    for (std::size_t i = 0; i < n; ++i) residual[i] = planar_residual(planar[i], arm.x).norm();
    for (const bool kind : {false, true}) {
      std::vector<double> of_kind;
      for (std::size_t i = 0; i < n; ++i)
        if (turning[i] == kind && step1[i] > 0.0) of_kind.push_back(residual[i]);
      const double s = std::max(robust_sigma(of_kind), 1e-6);
      for (std::size_t i = 0; i < n; ++i)
        if (turning[i] == kind) sigma[i] = s;
    }
  };
  for (int round = 0; round < 5; ++round) {
    judge();
    for (std::size_t i = 0; i < n; ++i) {
      const double r = residual[i] / (2.3849 * sigma[i]);
      weight[i] = step1[i] / (1.0 + r * r);
    }
    arm = fit_arm(planar, weight);
  }
  judge();

  MountingResult out;
  out.rotation = slam::rotation_from_rpy(Eigen::Vector3d(0.0, 0.0, arm.x.z())) * level;
  out.rpy = slam::rpy_of(out.rotation);
  out.lever_arm = arm.x.head<2>();

  double across_sq = 0.0, planar_sq = 0.0, before_sq = 0.0, weight_sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const bool outlier = step1[i] == 0.0 || residual[i] > o.outlier_sigmas * sigma[i];
    if (outlier) {
      ++out.outliers;
      continue;
    }
    ++out.windows;
    across_sq += across(ws[i], axis.u) * across(ws[i], axis.u);
    planar_sq += residual[i] * residual[i];
    weight_sum += weight[i];
    before_sq += planar_residual(planar[i], Eigen::Vector3d::Zero()).squaredNorm();
    if (turning[i]) ++out.turning_windows;
    else if (planar[i].body.norm() >= o.min_travel) ++out.straight_windows;
  }
  const double used = static_cast<double>(std::max<std::size_t>(out.windows, 1));
  out.rms_axis = std::sqrt(across_sq / used);
  out.rms_planar = std::sqrt(planar_sq / used);
  out.rms_planar_before = std::sqrt(before_sq / used);

  // Standard deviations from the residuals of what was used: u's direction
  // (roll and pitch) sigma / sqrt(sum |w|^2) over the spans (sigma per axis
  // across u); the arm and yaw sigma^2 (J^T W J)^-1 scaled to the weights.
  double source_sq = 0.0, source_turn_sq = 0.0, source_used = 0.0;
  for (std::size_t i = 0; i < axis_source.size(); ++i) {
    if (axis_weight[i] == 0.0) continue;
    source_sq += across(axis_source[i], axis.u) * across(axis_source[i], axis.u);
    source_turn_sq += axis_source[i].sensor_rotation.squaredNorm();
    source_used += 1.0;
  }
  out.axis_spans = &axis_source == &spans ? static_cast<std::size_t>(source_used) : 0;
  const double axis_sigma = std::sqrt(source_sq / std::max(1.0, 2.0 * source_used - 2.0));
  const double direction_sd = axis_sigma / std::sqrt(std::max(source_turn_sq, 1e-12));
  const double planar_var = planar_sq / std::max(1.0, 2.0 * used - 3.0);
  const Eigen::Matrix3d cov = planar_var * (weight_sum / used) * arm.information.inverse();
  out.rpy_sd = Eigen::Vector3d(direction_sd, direction_sd, std::sqrt(std::max(0.0, cov(2, 2))));
  if (ground) {
    out.from_ground = true;
    out.turns_to_ground = std::acos(std::clamp(turn_axis.dot(ground->normal), -1.0, 1.0));
    out.rpy_sd.head<2>().setConstant(ground->angle_sd);
  }
  out.lever_arm_sd = Eigen::Vector2d(std::sqrt(std::max(0.0, cov(0, 0))), std::sqrt(std::max(0.0, cov(1, 1))));
  out.lever_arm_observable = out.turning_windows >= kMinObserving && out.lever_arm_sd.allFinite();
  out.yaw_observable = out.straight_windows >= kMinObserving && std::isfinite(out.rpy_sd.z());
  return out;
}

}  // namespace adit::eval
