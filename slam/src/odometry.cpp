#include "adit/slam/odometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "start_search.hpp"

namespace adit::slam {
namespace {

void transform_into(std::span<const Eigen::Vector3f> in, const Eigen::Isometry3d& T, std::vector<Eigen::Vector3f>& out) {
  const Eigen::Isometry3f Tf = T.cast<float>();
  out.clear();
  for (const auto& p : in) out.push_back(Tf * p);
}

}  // namespace

bool wheel_motion_implausible(const Eigen::Isometry3d& wheel_delta, const Vector6d& velocity, double dt,
                              const OdometryConfig& config) {
  const Eigen::Isometry3d apart = exp_se3(velocity * dt).inverse() * wheel_delta;
  return apart.translation().norm() > config.max_wheel_disagreement_m ||
         Eigen::AngleAxisd(apart.linear()).angle() > config.max_wheel_disagreement_rad;
}

std::string_view to_string(OdometryStatus status) {
  switch (status) {
    case OdometryStatus::ok: return "ok";
    case OdometryStatus::first_scan: return "first scan";
    case OdometryStatus::too_few_points: return "too few points";
    case OdometryStatus::time_went_back: return "time went backwards";
    case OdometryStatus::degenerate: return "degenerate";
    case OdometryStatus::lost: return "lost";
    case OdometryStatus::relocalised: return "relocalised";
  }
  return "?";
}

Odometry::Odometry(const OdometryConfig& config, std::function<bool()> keeping_up)
    : config_(config),
      keeping_up_(std::move(keeping_up)),
      map_(config.map_voxel_m, config.map_capacity_voxels, config.map_point_spacing_m),
      downsampler_(config.max_scan_points),
      threshold_(config.initial_threshold_m, config.min_motion_m, config.max_range_m),
      registration_voxel_m_(config.registration_voxel_m),
      inertial_(config.inertial),
      inertial_registration_(config.registration) {
  inertial_registration_.point_sigma_m = config.inertial_point_sigma_m;
  // An IMU at 400 Hz over a 0.2 s sweep, with room.
  sweep_motion_.reserve(kSweepMotionCapacity);
  for (auto* buffer : {&deskewed_, &frame_, &source_, &registered_}) buffer->reserve(config.max_scan_points);
  for (auto* buffer : {&frame_times_, &source_times_}) buffer->reserve(config.max_scan_points);
  source_deskewed_.resize(config.max_scan_points);
  planes_.resize(config.max_scan_points);
}

OdometryResult Odometry::process(const ScanInput& scan, const std::optional<MotionPrior>& wheel) {
  OdometryResult result;
  result.stamp_ns = scan.stamp_ns;
  result.input_points = scan.points.size();
  if (started_ && scan.stamp_ns <= last_stamp_ns_) {
    result.pose = pose_;
    result.status = OdometryStatus::time_went_back;
    return result;
  }
  const double dt = started_ ? 1e-9 * static_cast<double>(scan.stamp_ns - last_stamp_ns_) : 0.0;
  if (dt > config_.max_scan_gap_s) {  // the sensor stopped: old motion means nothing
    velocity_.setZero();
    velocity_known_ = false;
    start_to_mid_.setIdentity();
    mid_offset_s_ = 0.0;
    reacquire_ = true;
  }

  // Prediction: wheel odometry when given, else constant velocity, carried
  // on from the middle of the last sweep (see the end of this function).
  const Eigen::Isometry3d constant_velocity_delta = start_to_mid_ * exp_se3(velocity_ * (dt - mid_offset_s_));
  const Eigen::Isometry3d delta = wheel ? wheel->delta : constant_velocity_delta;
  const Eigen::Isometry3d predicted = pose_ * delta;
  const Vector6d scan_velocity = wheel && dt > 0.0 ? Vector6d(log_se3(wheel->delta) / dt) : velocity_;

  // Finite points within range, downsampled as measured (a sweep moves
  // points by cm, voxels are dm); each kept point keeps its time, to be
  // deskewed once the sweep's motion is known (0 without firing times).
  const bool timed = scan.times_s.size() == scan.points.size();
  downsampler_.downsample(scan.points, timed ? scan.times_s : std::span<const float>{}, 0.5F * config_.map_voxel_m,
                          frame_, frame_times_, config_.min_range_m, config_.max_range_m);
  if (!timed) frame_times_.assign(frame_.size(), 0.0F);  // within reserved capacity
  downsampler_.downsample(frame_, frame_times_, registration_voxel_m_, source_, source_times_);
  result.registration_points = source_.size();
  result.registration_voxel_m = registration_voxel_m_;
  if (config_.target_registration_points > 0 && !source_.empty()) {
    const float ratio = static_cast<float>(source_.size()) / static_cast<float>(config_.target_registration_points);
    registration_voxel_m_ = std::clamp(registration_voxel_m_ * std::sqrt(ratio), config_.registration_voxel_m,
                                       std::max(config_.registration_voxel_m, config_.max_registration_voxel_m));
  }
  // frame_ deskewed with `velocity` into deskewed_.
  const auto deskew_frame = [&](const Vector6d& velocity) {
    deskewed_.resize(frame_.size());
    deskewer_.deskew(frame_, frame_times_, velocity, deskewed_);
    result.sweep_velocity = velocity;
  };

  float sweep_s = 0.0F;
  for (const float t : frame_times_) sweep_s = std::max(sweep_s, t);
  const bool inertial = inertial_started_ && started_ && predict_inertial(scan, static_cast<double>(sweep_s));

  if (source_.size() < config_.min_registration_points) {
    // Held on the prediction: the IMU's alone when there is one (dead reckoning).
    if (inertial) {
      deskewed_.resize(frame_.size());
      deskewer_.deskew(frame_, frame_times_, sweep_motion_, deskewed_);
      result.inertial = true;
    } else {
      deskew_frame(scan_velocity);
    }
    reacquire_ = true;
    pose_ = inertial ? inertial_.state().pose : predicted;
    start_to_mid_.setIdentity();
    mid_offset_s_ = 0.0;
    last_stamp_ns_ = scan.stamp_ns;
    started_ = true;
    result.pose = pose_;
    result.status = OdometryStatus::too_few_points;
    return result;
  }

  if (!started_ || map_.empty()) {
    if (scan.gravity) settle_up(*scan.gravity, scan.stamp_ns);
    // The map starts from this scan: with an IMU, deskewed by its rotation.
    start_inertial(scan, Matrix6d::Zero());
    if (inertial_started_ &&
        inertial_.predict_motion(scan.imu, 1e-9 * static_cast<double>(scan.stamp_ns) + sweep_s, sweep_motion_)) {
      deskewed_.resize(frame_.size());
      deskewer_.deskew(frame_, frame_times_, sweep_motion_, deskewed_);
      result.inertial = true;
    } else {
      deskew_frame(scan_velocity);
    }
    transform_into(deskewed_, pose_, registered_);
    map_.add(registered_);
    added_at_ = pose_;
    started_ = true;
    last_stamp_ns_ = scan.stamp_ns;
    result.pose = pose_;
    result.covariance = Matrix6d::Zero();  // the origin of the odometry frame, by definition
    result.status = OdometryStatus::first_scan;
    result.valid = true;
    return result;
  }

  if (inertial) {
    register_inertial(scan, wheel, result);
    return result;
  }

  PosePrior constant_velocity;
  constant_velocity.mean = pose_ * constant_velocity_delta;
  Vector6d information;
  const double translation_sigma = config_.max_acceleration_mps2 > 0.0 && dt > 0.0
                                       ? 0.5 * config_.max_acceleration_mps2 * dt * dt
                                       : config_.constant_velocity_sigma_m;
  information.head<3>().setConstant(1.0 / (translation_sigma * translation_sigma));
  information.tail<3>().setConstant(1.0 / (config_.constant_velocity_sigma_rad * config_.constant_velocity_sigma_rad));
  constant_velocity.information = information.asDiagonal();
  if (scan.gravity && up_frame_ && scan.gravity->sigma_rad > 0.0)
    constant_velocity.gravity = {scan.gravity->up, *up_frame_, 1.0 / (scan.gravity->sigma_rad * scan.gravity->sigma_rad)};
  PosePrior prior = constant_velocity;
  if (wheel) {
    prior.mean = predicted;
    // The motion's covariance is in the body frame at the prediction, where the prior lives.
    prior.information = wheel->covariance.inverse();
    if (!prior.information.allFinite()) prior.information.setZero();
  }

  // After a gap or a lost scan the prediction is poor: search as widely as at the start.
  const double sigma = reacquire_ ? config_.initial_threshold_m / 3.0 : threshold_.sigma();
  reacquire_ = false;
  SweepMotion sweep;
  sweep.times_s = source_times_;
  sweep.velocity = scan_velocity;
  sweep.estimate = config_.estimate_sweep_velocity;
  Vector6d sweep_information;
  sweep_information.head<3>().setConstant(1.0 / (config_.sweep_velocity_sigma_mps * config_.sweep_velocity_sigma_mps));
  sweep_information.tail<3>().setConstant(1.0 / (config_.sweep_velocity_sigma_radps * config_.sweep_velocity_sigma_radps));
  sweep.information = sweep_information.asDiagonal();
  // The wheels know the planar part of the sweep's motion as well as the
  // scan-to-scan motion: a velocity is the delta over dt, so its covariance
  // is the delta's over dt² (the directions they do not see stay loose).
  if (wheel && dt > 0.0) {
    const Matrix6d wheel_information = (wheel->covariance / (dt * dt)).inverse();
    if (wheel_information.allFinite()) sweep.information = wheel_information;
  }
  sweep.deskewed = std::span(source_deskewed_).first(source_.size());
  const auto register_from = [&](const PosePrior& start, const SweepMotion& motion) {
    return register_scan(source_, map_, start, 3.0 * sigma, sigma / 3.0, config_.registration, planes_, motion,
                         prior_term(config_.registration.point_sigma_m));
  };
  // An alternative start replaces the registration only when it explains
  // clearly more of the scan: where the scan cannot tell, the first keeps it.
  result.registration = register_from(prior, sweep);
  // Wheels that slipped (or a wrong encoder) put the prediction where the
  // scan no longer overlaps the map: far fewer correspondences than the last
  // scan had. A wheel that spins a little (3° of false turn per scan, seen
  // on simulated 30-minute sessions) keeps the overlap but departs from any
  // plausible change of motion. Either way the constant-velocity prediction
  // is tried too, and the registration that explains more of the scan wins
  // (docs/decisions/006-wheel-spin-check.md).
  const auto enough = [&](const RegistrationResult& r) {
    return static_cast<double>(r.correspondences) >= config_.min_correspondence_share * last_correspondences_;
  };
  if (wheel && (!enough(result.registration) || wheel_motion_implausible(wheel->delta, velocity_, dt, config_))) {
    SweepMotion constant_sweep = sweep;
    constant_sweep.velocity = velocity_;
    constant_sweep.information = sweep_information.asDiagonal();
    const RegistrationResult alternative = register_from(constant_velocity, constant_sweep);
    if (explains_clearly_more(alternative, result.registration, config_.wheel_rejection_margin)) {
      result.registration = alternative;
      result.wheel_rejected = true;
    }
  }
  // A turn the prediction missed (a hand-held scanner jerked round): the
  // registration collapses to a fraction of the last scan's correspondences,
  // and one registration does not pull in from beyond a few degrees. It is
  // started again from turns of the prediction about the body's z
  // (docs/decisions/042-rotation-search-and-patient-kernel.md).
  const bool collapsed = last_correspondences_ > 0.0 && !enough(result.registration);
  if (!wheel && dt > 0.0 && velocity_known_ && collapsed) {
    const double wide = config_.initial_threshold_m / 3.0;
    const double reach = std::min(config_.max_turn_rate_radps * dt,
                                  0.5 * config_.max_rotation_starts * config_.rotation_search_step_rad);
    result.search_cut |= !search_rotation(reach, config_.rotation_search_step_rad, config_.wheel_rejection_margin,
                    config_.start_search_noise_sigmas, [this] { return keeping_up(); },
                    [&](double yaw) {
                      PosePrior start = constant_velocity;
                      start.mean = constant_velocity.mean * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
                      SweepMotion turning = sweep;
                      turning.velocity(5) += yaw / dt;  // the turn made over the interval
                      return register_scan(source_, map_, start, 3.0 * wide, wide / 3.0, config_.registration, planes_,
                                           turning, prior_term(config_.registration.point_sigma_m));
                    },
                    result.registration);
  }
  // No velocity known yet (the first registration, or after the sensor
  // stopped): the prediction is "standing still", but the sensor may already
  // be moving. On hdl64-urban-22 a car at 27 km/h moves 0.74 m per scan, and
  // the scan fits "still" well enough to stay there for good: the ground and
  // the walls along the street say nothing of the motion along it, and what
  // stands across it lies beyond the plane search's reach (one map voxel), so
  // the odometry crept along at 0.1 m per scan. The registration is also
  // started from offsets along the body's x and y axes, and one that explains
  // clearly more of the scan wins (as a slipped wheel is overruled above;
  // docs/decisions/012-start-search.md).
  if (!wheel && !velocity_known_ && dt > 0.0) {
    result.search_cut |= !search_start(config_.max_start_speed_mps * dt, config_.start_search_step_m,
                 config_.wheel_rejection_margin, config_.start_search_noise_sigmas, [this] { return keeping_up(); },
                 [&](const Eigen::Vector2d& offset) {
                   PosePrior start = constant_velocity;
                   start.mean = constant_velocity.mean * Eigen::Translation3d(offset.x(), offset.y(), 0.0);
                   SweepMotion moving = sweep;
                   moving.velocity.head<2>() += offset / dt;
                   return register_from(start, moving);
                 },
                 result.registration);
  }
  // Lost: the searches found nothing that fits as the last tracked scan did
  // (a view filled by something passing, a turn beyond the search). A wrong
  // pose in the map would corrupt every scan after it, so the scan is held on
  // the prediction, kept out of the map, and the next one searched from wide
  // (decision 043).
  const bool relocalised = lost_scans_ > 0;
  if (last_correspondences_ > 0.0 && lost_scans_ < config_.max_lost_scans &&
      static_cast<double>(result.registration.correspondences) <
          config_.lost_correspondence_share * last_correspondences_) {
    ++lost_scans_;
    reacquire_ = true;
    pose_ = predicted;
    start_to_mid_.setIdentity();
    mid_offset_s_ = 0.0;
    last_stamp_ns_ = scan.stamp_ns;
    result.pose = pose_;
    result.status = OdometryStatus::lost;
    return result;
  }
  lost_scans_ = 0;
  velocity_known_ = true;
  last_correspondences_ = static_cast<double>(result.registration.correspondences);
  const Eigen::Isometry3d corrected = result.registration.pose;

  threshold_.update(predicted.inverse() * corrected, pose_.inverse() * corrected);
  // A scan pins its mid-sweep pose down far better than how the sweep's
  // motion splits between its start pose and its velocity ξ (a start pose off
  // by +e with ξ off the other way fits almost as well). Differencing start
  // poses, T_{k-1}⁻¹·T_k, let such an error come back amplified in the next
  // prediction: a drone hovering while it turned at 60°/s rolled ±1° in
  // alternate scans, growing. So the velocity is the motion between sweep
  // middles, M_k = T_k·exp(ξ_k·τ_k/2), and the prediction continues it from
  // M_k (trajectory continuity between scans as in CT-ICP, Dellenbach et al.
  // 2022, §III-B, with the better-observed pose as the anchor).
  // Not with wheels: their covariance over dt² is ξ's prior, so ξ is theirs,
  // and a spinning wheel's false turn would enter the sweep middles and with
  // them the constant velocity that is the check against that wheel
  // (docs/decisions/002-sweep-middle-velocity.md).
  // There the velocity stays the difference of the start poses, which the
  // scan corrects.
  float duration = 0.0F;
  for (const float t : source_times_) duration = std::max(duration, t);
  const double half = wheel ? 0.0 : 0.5 * static_cast<double>(duration);
  const Eigen::Isometry3d start_to_mid = exp_se3(result.registration.sweep_velocity * half);
  const double mid_to_mid = dt - mid_offset_s_ + half;
  if (mid_to_mid > 0.0) velocity_ = log_se3((pose_ * start_to_mid_).inverse() * corrected * start_to_mid) / mid_to_mid;
  start_to_mid_ = start_to_mid;
  mid_offset_s_ = half;
  pose_ = corrected;
  last_stamp_ns_ = scan.stamp_ns;
  if (scan.gravity) settle_up(*scan.gravity, scan.stamp_ns);

  deskew_frame(result.registration.sweep_velocity);
  add_deskewed_to_map();

  result.pose = pose_;
  result.covariance = result.registration.covariance;
  result.valid = true;
  result.status = relocalised                     ? OdometryStatus::relocalised
                  : result.registration.degenerate ? OdometryStatus::degenerate
                                                   : OdometryStatus::ok;
  // The IMU did not cover this scan (a dropout, or it just began): the
  // filter starts again from the scan's pose.
  const Eigen::Isometry3d to_body = pose_.inverse();
  start_inertial(scan, adjoint(to_body) * result.covariance * adjoint(to_body).transpose());
  return result;
}

void Odometry::anchor_to_prior(const VoxelHashMap& prior_index, const Eigen::Isometry3d& prior_from_odometry) {
  prior_planes_.resize(planes_.size());
  prior_map_ = {&prior_index, prior_from_odometry, 1.0, {}};
}

PriorMapTerm Odometry::prior_term(double local_sigma_m) {
  PriorMapTerm term = prior_map_;
  if (term.index == nullptr) return term;
  term.planes = prior_planes_;
  term.weight = (local_sigma_m * local_sigma_m) / (config_.prior_map_sigma_m * config_.prior_map_sigma_m);
  term.stride = config_.prior_map_stride;
  return term;
}

void Odometry::release_prior() { prior_map_ = {}; }

std::optional<Eigen::Isometry3d> Odometry::prior_from_odometry() const {
  if (prior_map_.index == nullptr) return std::nullopt;
  return prior_map_.prior_from_frame;
}

std::optional<Eigen::Vector3d> Odometry::up() const {
  if (inertial_started_) return -inertial_.state().gravity.normalized();
  return up_frame_;
}

void Odometry::add_deskewed_to_map() {
  if (!moved_since(added_at_, pose_, config_.map_insertion)) return;
  added_at_ = pose_;
  transform_into(deskewed_, pose_, registered_);
  map_.add(registered_);
  if ((pose_.translation() - removed_far_at_).norm() >= config_.map_removal_step_m) {
    map_.remove_far(pose_.translation().cast<float>(), config_.max_range_m);
    removed_far_at_ = pose_.translation();
  }
}

void Odometry::settle_up(const UpMeasurement& gravity, std::int64_t stamp_ns) {
  if (!(gravity.sigma_rad > 0.0)) return;
  if (!up_frame_) first_up_ns_ = stamp_ns;
  else if (1e-9 * static_cast<double>(stamp_ns - first_up_ns_) > config_.gravity_settle_s) return;
  up_sum_ += (pose_.linear() * gravity.up) / (gravity.sigma_rad * gravity.sigma_rad);
  up_frame_ = up_sum_.normalized();
}

}  // namespace adit::slam
