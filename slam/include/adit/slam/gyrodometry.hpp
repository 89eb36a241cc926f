#pragma once
// Gyrodometry: a wheeled robot's motion prior with the wheels' translation and
// the gyroscope's rotation (Borenstein and Feng, "Gyrodometry: a new method
// for combining data from gyros and odometry in mobile robots", ICRA 1996).
// The wheels' heading is off in every turn by their radii's error (0.4 % of
// the turn) and by a slip's travel (degrees); a gyroscope's by its bias times
// the interval, and the bias is learnt whenever the wheels stand still.
// The roll and pitch the wheels cannot see come from the gyroscope too.
// (docs/decisions/052-gyrodometry.md)

#include <cstddef>
#include <optional>
#include <span>

#include <Eigen/Geometry>

#include "adit/slam/imu_sample.hpp"
#include "adit/slam/odometry.hpp"

namespace adit::slam {

struct GyroNoise {
  double rate_density = 1.7e-4;         // rad/s/√Hz: the datasheet's angle random walk (learns the bias)
  double model_error_density = 0.02;    // rad/s/√Hz: what it leaves out, in the rotation's σ (InertialConfig's)
  double bias_walk = 1.9e-5;    // rad/s²/√Hz
  double scale_error = 0.005;   // of the turn: a MEMS gyroscope's scale-factor error after calibration
  double initial_bias_sigma = 0.01;  // rad/s: a MEMS unit's turn-on bias before any standstill
  double max_gap_s = 0.05;      // readings further apart are a dropout
};

// The body's rotation from t0 to t1 (R_t0⁻¹·R_t1) integrated from gyroscope
// readings in the body frame (the LiDAR-inertial filter's midpoint rule, the
// ends interpolated) with `bias` removed; nullopt unless the readings cover
// [t0, t1] as the filter requires (none further apart than max_gap_s, nor
// further than that from either end) and all carry a gyroscope.
std::optional<Eigen::Matrix3d> gyro_rotation(std::span<const ImuSample> readings, double t0, double t1,
                                             const Eigen::Vector3d& bias, double max_gap_s);

// Whether an axis of the gyroscope read one value in every reading within
// [t0, t1], at least `min_readings` of them: stuck (daemon::ImuMonitor counts
// an axis stuck after 100 such readings; a MEMS unit's noise moves every axis
// by several steps per reading, so even a still one does not repeat).
bool gyro_stuck(std::span<const ImuSample> readings, double t0, double t1, std::size_t min_readings = 8);

// The gyroscope's bias, the same on each axis in its uncertainty: a Kalman
// filter on a random walk, measured by the mean rate over each stretch the
// body stood still. A mean rate further from the bias than three σ of their
// difference on any axis is refused: wheels still at a motion's onset while
// the body already rocks or turns.
class GyroBias {
 public:
  explicit GyroBias(const GyroNoise& noise) : noise_(noise) {}
  // The body stood still over [t0, t1] and the gyroscope read `mean_rate`;
  // false when refused.
  bool still(const Eigen::Vector3d& mean_rate, double t0, double t1);
  const Eigen::Vector3d& bias() const { return bias_; }
  // σ of the bias at time t, rad/s: grown by the walk since the last stillness.
  double sigma(double t) const;
  bool learnt() const { return learnt_; }

 private:
  GyroNoise noise_;
  Eigen::Vector3d bias_ = Eigen::Vector3d::Zero();
  double variance_ = 0.0;  // with learnt_: at time at_
  double at_ = 0.0;
  bool learnt_ = false;
};

// The wheels' prior with its rotation replaced by the gyroscope's over the
// same interval `dt` and that rotation's covariance: white noise, the bias's
// σ, and the scale-factor error, per axis. Translation as the wheels had it.
// nullopt when the two rotations differ by more than the wheels' covariance
// and the gyroscope's own error (without the model error) together allow (χ²
// with 3 degrees of freedom beyond its 99.9 % point, 16.27): a gyroscope stuck
// or failed, or a slip far beyond the wheels' σ; the wheels' prior stands.
std::optional<MotionPrior> gyro_aided(const MotionPrior& wheels, const Eigen::Matrix3d& rotation, double dt,
                                      double bias_sigma, const GyroNoise& noise);

}  // namespace adit::slam
