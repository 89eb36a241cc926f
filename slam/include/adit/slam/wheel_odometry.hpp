#pragma once
// Wheel odometry for differential-drive and skid-steer ground robots, from
// wheel rim speeds or from encoder counts. Pure: no I/O, no clocks; the caller
// passes each sample's time.
//
// Kinematics: ds = (ds_l + ds_r) / 2, dtheta = (ds_r - ds_l) / b_eff, and the
// pose moves along the chord at mid-heading (Siegwart, Nourbakhsh, Scaramuzza,
// "Introduction to Autonomous Mobile Robots", 2nd ed., §5.2.4, eq. 5.5-5.7).
// Skid steer: the wheels slip sideways while turning, so the vehicle turns
// as if the track were wider: b_eff = track_width * skid_factor (the ICR
// expansion factor of Mandow et al., "Experimental kinematics for wheeled
// skid-steer mobile robots", IROS 2007). skid_factor = 1 is differential drive.
//
// Covariance: the same book's error model (eq. 5.8-5.11): each wheel's travel
// has variance k|ds_i|, propagated with the Jacobians of the kinematics:
//   P' = F_p P F_p^T + F_d diag(k_r|ds_r|, k_l|ds_l|) F_d^T + diag(0, 0, k_turn |dtheta|)
// The last term, ours, covers heading error from slip while turning, which the
// wheel-only model misses on skid-steer vehicles.
//
// Bad samples are flagged and not integrated blindly: time going backwards
// (dropped), gaps longer than max_gap (baseline reset, nothing integrated),
// speeds or counter jumps no vehicle can do (the interval is integrated at the
// last trusted speeds and the sample is not trusted; after max_rejected in a
// row the new values are accepted as the new baseline).
//
// Wheel slip: a wheel whose speed changes faster than max_acceleration allows
// (over at least min_interval, plus the measurement's own noise) spins or
// locks: its traction is gone, so its travel says nothing of the ground. A
// slip lasts (the simulator's robot: one wheel 30 % fast for 0.3 s; on loose
// rock, as long as the wheel spins), so each wheel has a slip episode: that
// wheel is integrated at the speed it would have with traction (the other
// wheel's speed with the turn rate from before the slip; if both slip, its own
// speed from before) until its measured speed comes back within the same
// bound of that, or until max_slip_duration, after which the new speed is
// accepted (a real change). The other wheel is used as measured. Counts: the slipping wheel's counts are discarded, not carried
// into the next reading. This is the wheel-acceleration test of traction
// control (a wheel cannot accelerate beyond what friction allows, about µ·g),
// e.g. Gustafsson, "Slip-based tire-road friction estimation", Automatica
// 33(6), 1997, which estimates slip from wheel speeds against the vehicle's
// (docs/decisions/005-wheel-slip-held.md).

#include <array>
#include <cstdint>
#include <limits>

#include <Eigen/Core>

#include "adit/slam/pose2.hpp"

namespace adit::slam {

// Binds to the `wheel_odometry:` config section.
struct WheelGeometry {
  double left_radius = 0.1;   // m, for encoder counts and wheel angular rates
  double right_radius = 0.1;  // m
  double track_width = 0.5;   // m between the left and right wheels' contact lines
  double skid_factor = 1.0;   // effective track = track_width * skid_factor (>= 1 for skid steer)
  double left_scale = 1.0;    // calibration: multiplies the left wheel's travel
  double right_scale = 1.0;   // calibration: multiplies the right wheel's travel
  double counts_per_revolution = 4096.0;  // encoder counts per wheel revolution (after gearing)
  unsigned counter_bits = 32;             // encoder counter width, for wrap-around (1..64)

  double effective_track() const { return track_width * skid_factor; }
};

struct WheelNoise {
  double k_left = 1e-4;   // m^2 per m travelled by the left wheel (Siegwart's k_l)
  double k_right = 1e-4;  // m^2 per m travelled by the right wheel (k_r)
  double k_turn = 1e-4;   // rad^2 per rad turned
};

struct WheelLimits {
  double max_speed = 15.0;         // m/s per wheel; faster is a glitch
  double max_acceleration = 15.0;  // m/s^2 per wheel between samples; more is slip or a glitch
  double min_interval = 0.02;      // s: accelerations are judged over at least this long, because
                                   // loggers bunch frames (timestamps jitter by milliseconds)
  double speed_noise = 0.2;        // m/s: a jump this big between reported speeds is measurement noise, never slip
  double count_noise = 2.0;        // counts: a speed from counts is uncertain by this many counts over its interval
  double timestamp_jitter = 0.001; // s: and by its speed times this over its interval (frames stamped late or early)
  double max_slip_duration = 1.0;  // s: a wheel held longer than this is re-baselined at its new speed
  double max_gap = 0.5;            // s between samples; longer is a gap
  unsigned max_rejected = 5;       // consecutive impossible samples before re-baselining
};

enum class WheelStep : std::uint8_t {
  integrated,     // interval integrated normally
  first,          // baseline sample, nothing to integrate yet
  time_backwards, // time not after the previous sample: dropped
  gap,            // too long since the previous sample: baseline reset, nothing integrated
  impossible,     // speed or counter jump beyond max_speed: held at the last trusted speed
  slip,           // a wheel slips (acceleration beyond max_acceleration): it is held at its last trusted speed
  rebaselined,    // accepted after max_rejected impossible samples or max_slip_duration of slip
};

struct WheelOdometryStats {
  std::uint64_t integrated = 0;
  std::uint64_t time_backwards = 0;
  std::uint64_t gaps = 0;
  std::uint64_t impossible = 0;
  std::uint64_t slips = 0;          // samples with a wheel held for slip
  std::uint64_t slip_episodes = 0;  // times a wheel started to slip
  std::uint64_t rebaselined = 0;
  std::uint64_t counter_wraps = 0;
};

// Signed difference of two readings of a `bits`-wide counter that may have
// wrapped (modular arithmetic, result in [-2^(bits-1), 2^(bits-1))).
std::int64_t counter_delta(std::uint64_t previous, std::uint64_t current, unsigned bits);

// One odometry increment: pose moved by wheel travels ds_left, ds_right (m,
// already scaled), with covariance propagated as described above.
void integrate_wheel_travel(Pose2& pose, Eigen::Matrix3d& covariance, double ds_left, double ds_right,
                            double effective_track, const WheelNoise& noise);

class WheelOdometry {
 public:
  WheelOdometry(const WheelGeometry& geometry, const WheelNoise& noise = {}, const WheelLimits& limits = {});

  // Wheel rim speeds in m/s (before left/right_scale), time in seconds.
  WheelStep add_speeds(double t, double v_left, double v_right);
  // Wheel angular rates in rad/s, multiplied by the radii.
  WheelStep add_wheel_rates(double t, double w_left, double w_right);
  // Raw encoder counters (counter_bits wide, wrapping).
  WheelStep add_counts(double t, std::uint64_t left, std::uint64_t right);

  const Pose2& pose() const { return pose_; }
  const Eigen::Matrix3d& covariance() const { return covariance_; }
  double distance() const { return distance_; }  // m travelled by the vehicle centre, summed |ds|
  const WheelOdometryStats& stats() const { return stats_; }
  void reset(const Pose2& pose = {});

 private:
  WheelStep step(double t, double v_left, double v_right, bool from_counts);

  // Which wheels slip at this reading (time t, dt after the last), and the
  // speeds to integrate: as measured, or a slipping wheel's speed with
  // traction. Starts, continues and ends each wheel's slip episode.
  struct TractionCheck {
    std::array<double, 2> speeds;   // left, right, m/s
    std::array<double, 2> earlier;  // the next reading's "speeds before the last"
    bool slipping = false;
    bool accepted_after_slip = false;  // a wheel held for max_slip_duration: its new speed is taken
  };
  TractionCheck check_traction(double t, double dt, const std::array<double, 2>& measured, bool from_counts);

  WheelGeometry geometry_;
  WheelNoise noise_;
  WheelLimits limits_;
  Pose2 pose_;
  Eigen::Matrix3d covariance_ = Eigen::Matrix3d::Zero();
  double distance_ = 0.0;
  bool have_previous_ = false;
  double t_previous_ = 0.0;
  double v_left_previous_ = 0.0;  // last trusted speeds, m/s
  double v_right_previous_ = 0.0;
  bool have_counts_ = false;
  std::uint64_t left_count_ = 0;
  std::uint64_t right_count_ = 0;
  unsigned rejected_in_a_row_ = 0;
  static constexpr double kNotSlipping = std::numeric_limits<double>::quiet_NaN();
  // Per wheel (0 left, 1 right): slipping since when (NaN: not slipping).
  std::array<double, 2> slip_since_{kNotSlipping, kNotSlipping};
  std::array<double, 2> slip_ended_{kNotSlipping, kNotSlipping};  // when its last slip ended by gripping (NaN: none)
  std::array<double, 2> slip_offset_{};  // this wheel's speed minus the other's before the slip
  std::array<double, 2> slip_speed_{};   // this wheel's speed before the slip
  bool speeds_known_ = false;  // the trusted speeds were measured (counts: after two readings)
  std::array<double, 2> earlier_speed_{};  // the trusted speeds before the last ones, and their time
  double earlier_t_ = 0.0;
  bool earlier_known_ = false;
  WheelOdometryStats stats_;
};

}  // namespace adit::slam
