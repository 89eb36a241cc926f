#pragma once
// The correspondence threshold from the motion prediction's observed error
// (KISS-ICP, Vizzo et al. 2023, §III-D, eq. 6–8): the deviation between the
// predicted and the registered pose, turned into a point displacement bound
// at the sensor's range, is averaged over the scans that moved at least
// min_motion; the threshold is 3σ of it.

#include <cmath>

#include <Eigen/Geometry>

namespace adit::slam {

class AdaptiveThreshold {
 public:
  AdaptiveThreshold(double initial_threshold_m, double min_motion_m, double max_range_m)
      : initial_threshold_m_(initial_threshold_m), min_motion_m_(min_motion_m), max_range_m_(max_range_m) {}

  // σ of the model error; the correspondence threshold is 3σ and the robust
  // kernel's starting scale σ/3 (KISS-ICP's choice).
  double sigma() const {
    return samples_ == 0 ? initial_threshold_m_ / 3.0 : std::sqrt(sum_squared_error_ / static_cast<double>(samples_));
  }

  // `deviation` = predicted⁻¹ · registered; `motion` = previous⁻¹ · registered.
  void update(const Eigen::Isometry3d& deviation, const Eigen::Isometry3d& motion) {
    if (motion.translation().norm() < min_motion_m_) return;
    const double theta = Eigen::AngleAxisd(deviation.linear()).angle();
    const double rotation_error = 2.0 * max_range_m_ * std::sin(theta / 2.0);  // eq. 7
    const double error = rotation_error + deviation.translation().norm();
    sum_squared_error_ += error * error;
    ++samples_;
  }

 private:
  double initial_threshold_m_;
  double min_motion_m_;
  double max_range_m_;
  double sum_squared_error_ = 0.0;
  long samples_ = 0;
};

}  // namespace adit::slam
