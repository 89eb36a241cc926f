#include "bench_wheels.hpp"

#include <algorithm>
#include <cmath>

#include "adit/common/error.hpp"
#include "adit/config/load.hpp"
#include "adit/drivers/can/candump.hpp"
#include "adit/drivers/can/decoder.hpp"
#include "adit/drivers/can/dbc.hpp"
#include "adit/slam/lie.hpp"
#include "adit/slam/wheel_odometry.hpp"

namespace adit::tools {
namespace {

namespace can = adit::drivers::can;

std::vector<can::MessageSpec> wheel_messages(const config::Config& c) {
  std::vector<can::MessageSpec> messages;
  if (!c.can.dbc.empty()) messages = can::load_dbc(c.can.dbc).messages;
  for (const config::CanSignal& s : c.can.signals) {
    can::SignalSpec spec;
    spec.name = s.name;
    spec.start_bit = static_cast<unsigned>(s.start_bit);
    spec.length = static_cast<unsigned>(s.length);
    spec.byte_order = s.byte_order == config::ByteOrder::motorola ? can::ByteOrder::motorola : can::ByteOrder::intel;
    spec.is_signed = s.value_type == config::ValueType::signed_int;
    spec.type = s.value_type == config::ValueType::ieee_float ? (s.length == 64 ? can::ValueType::float64 : can::ValueType::float32)
                                                              : can::ValueType::integer;
    spec.factor = s.factor;
    spec.offset = s.offset;
    spec.unit = s.unit;
    can::add_inline_signal(messages, s.id, s.extended, spec);
  }
  return messages;
}

Eigen::Isometry3d to_isometry(const config::Transform& t) {
  const double k = M_PI / 180.0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(t.rpy_deg[2] * k, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(t.rpy_deg[1] * k, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(t.rpy_deg[0] * k, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() << t.xyz_m[0], t.xyz_m[1], t.xyz_m[2];
  return T;
}

Eigen::Isometry3d planar(const slam::Pose2& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(p.theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << p.x, p.y, 0.0;
  return T;
}

// Linear interpolation of the track at t (heading unwrapped over the step).
slam::Pose2 pose_at(const WheelTrack& track, double t, double& distance) {
  const auto it = std::lower_bound(track.t.begin(), track.t.end(), t);
  const auto i = static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(it - track.t.begin(), 1, static_cast<std::ptrdiff_t>(track.t.size()) - 1));
  const double a = std::clamp((t - track.t[i - 1]) / (track.t[i] - track.t[i - 1]), 0.0, 1.0);
  const slam::Pose2& p = track.pose[i - 1];
  const slam::Pose2& q = track.pose[i];
  distance = track.distance[i - 1] + a * (track.distance[i] - track.distance[i - 1]);
  return {p.x + a * (q.x - p.x), p.y + a * (q.y - p.y), p.theta + a * slam::wrap_angle(q.theta - p.theta)};
}

}  // namespace

WheelTrack load_wheel_track(const std::string& config_file) {
  const config::Config c = config::load_config(config_file);
  const auto& w = c.wheel_odometry;
  if (!c.can.enabled || !w.enabled || c.can.source != config::CanSource::candump)
    throw InputError(config_file, "wheel_odometry", "needs can.enabled with source candump and wheel_odometry.enabled");
  const std::vector<can::MessageSpec> messages = wheel_messages(c);
  const std::vector<std::string> wanted{w.left_signal, w.right_signal};
  can::SignalDecoder decoder(messages, wanted, w.quantity != config::WheelQuantity::counts);
  const auto left = static_cast<std::size_t>(decoder.slot(w.left_signal));
  const auto right = static_cast<std::size_t>(decoder.slot(w.right_signal));

  slam::WheelGeometry g;
  g.left_radius = w.left_radius_m;
  g.right_radius = w.right_radius_m;
  g.track_width = w.track_width_m;
  g.counts_per_revolution = w.counts_per_revolution;
  g.counter_bits = static_cast<unsigned>(w.counter_bits);
  slam::WheelOdometry odometry(g);
  WheelTrack track;
  track.extrinsics = to_isometry(c.lidar.extrinsics);

  // Left and right may come in separate frames (the sim's two TPDOs): a
  // sample is taken when both have a value newer than the last sample.
  std::vector<double> values(decoder.slot_count());
  double value_left = NAN;
  double value_right = NAN;
  can::CandumpReader reader(c.can.log);
  can::Frame frame;
  while (reader.next(frame)) {
    const can::DecodeResult r = decoder.decode(frame, values);
    if (r.status != can::DecodeStatus::decoded) continue;
    const auto written = [&](std::size_t slot) { return slot >= r.first && slot < r.first + r.count && !std::isnan(values[slot]); };
    if (written(left)) value_left = values[left];
    if (written(right)) value_right = values[right];
    if (std::isnan(value_left) || std::isnan(value_right)) continue;
    const double t = 1e-6 * static_cast<double>(frame.time_us) - w.time_offset_s;
    slam::WheelStep step;
    switch (w.quantity) {
      case config::WheelQuantity::counts:
        step = odometry.add_counts(t, static_cast<std::uint64_t>(static_cast<std::int64_t>(value_left)),
                                   static_cast<std::uint64_t>(static_cast<std::int64_t>(value_right)));
        break;
      case config::WheelQuantity::angular_speed: step = odometry.add_wheel_rates(t, value_left, value_right); break;
      default: step = odometry.add_speeds(t, value_left, value_right); break;
    }
    value_left = value_right = NAN;
    if (step != slam::WheelStep::integrated && step != slam::WheelStep::first) ++track.rejected;
    if (step == slam::WheelStep::time_backwards) continue;
    track.t.push_back(t);
    track.pose.push_back(odometry.pose());
    track.distance.push_back(odometry.distance());
  }
  if (track.t.size() < 2) throw InputError(c.can.log, "wheel_odometry", "fewer than 2 wheel samples decoded");
  return track;
}

std::optional<slam::MotionPrior> wheel_prior(const WheelTrack& track, double t0, double t1) {
  if (t0 < track.t.front() || t1 > track.t.back() || !(t1 > t0)) return std::nullopt;
  double d0 = 0.0;
  double d1 = 0.0;
  const slam::Pose2 p0 = pose_at(track, t0, d0);
  const slam::Pose2 p1 = pose_at(track, t1, d1);
  const Eigen::Isometry3d body = planar(p0).inverse() * planar(p1);
  slam::MotionPrior prior;
  prior.delta = track.extrinsics.inverse() * body * track.extrinsics;
  // Body frame: a per-cent of the distance along the ground plus a floor
  // (slip, quantisation), a per-cent of the turn in yaw; the wheels say
  // nothing about height, roll and pitch, so those are loose.
  const double ds = std::abs(d1 - d0);
  const double turn = std::abs(slam::wrap_angle(p1.theta - p0.theta));
  const double s_xy = 0.01 + 0.02 * ds;
  const double s_yaw = 0.005 + 0.05 * turn + 0.005 * ds;
  slam::Vector6d sigma;
  sigma << s_xy, s_xy, 0.05, 0.02, 0.02, s_yaw;
  const slam::Matrix6d body_covariance = sigma.cwiseAbs2().asDiagonal();
  const slam::Matrix6d Ad = slam::adjoint(track.extrinsics.inverse());
  prior.covariance = Ad * body_covariance * Ad.transpose();
  return prior;
}

}  // namespace adit::tools
