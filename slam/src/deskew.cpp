#include "adit/slam/deskew.hpp"

#include <algorithm>

namespace adit::slam {

template <int Bins>
void TabulatedDeskewer<Bins>::deskew(std::span<const Eigen::Vector3f> points, std::span<const float> times_s,
                      const Vector6d& velocity, std::span<Eigen::Vector3f> out) {
  float duration = 0.0F;
  for (const float t : times_s) duration = std::max(duration, t);
  if (duration <= 0.0F || velocity.isZero()) {
    std::copy(points.begin(), points.end(), out.begin());
    return;
  }
  const float bin_width = duration / static_cast<float>(kBins - 1);
  for (int i = 0; i < kBins; ++i) {
    const Eigen::Isometry3d T = exp_se3(velocity * static_cast<double>(static_cast<float>(i) * bin_width));
    rotations_[static_cast<std::size_t>(i)] = T.linear().cast<float>();
    translations_[static_cast<std::size_t>(i)] = T.translation().cast<float>();
  }
  apply(points, times_s, bin_width, out);
}

template <int Bins>
void TabulatedDeskewer<Bins>::deskew(std::span<const Eigen::Vector3f> points, std::span<const float> times_s,
                                     std::span<const TimedPose> motion, std::span<Eigen::Vector3f> out) {
  float duration = 0.0F;
  for (const float t : times_s) duration = std::max(duration, t);
  if (duration <= 0.0F || motion.empty()) {
    std::copy(points.begin(), points.end(), out.begin());
    return;
  }
  const float bin_width = duration / static_cast<float>(kBins - 1);
  std::size_t j = 0;  // motion[j].t <= tau < motion[j + 1].t, walking forward with tau
  for (int i = 0; i < kBins; ++i) {
    const double tau = static_cast<double>(static_cast<float>(i) * bin_width);
    while (j + 1 < motion.size() && motion[j + 1].t <= tau) ++j;
    Eigen::Isometry3d T = motion[j].pose;
    if (j + 1 < motion.size() && tau > motion[j].t) {
      const double s = (tau - motion[j].t) / (motion[j + 1].t - motion[j].t);
      T = motion[j].pose * exp_se3(s * log_se3(motion[j].pose.inverse() * motion[j + 1].pose));
    }
    rotations_[static_cast<std::size_t>(i)] = T.linear().cast<float>();
    translations_[static_cast<std::size_t>(i)] = T.translation().cast<float>();
  }
  apply(points, times_s, bin_width, out);
}

template <int Bins>
void TabulatedDeskewer<Bins>::apply(std::span<const Eigen::Vector3f> points, std::span<const float> times_s,
                                    float bin_width, std::span<Eigen::Vector3f> out) const {
  const float inverse_bin = 1.0F / bin_width;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const int bin = std::clamp(static_cast<int>(times_s[k] * inverse_bin + 0.5F), 0, kBins - 1);
    const auto b = static_cast<std::size_t>(bin);
    out[k] = rotations_[b] * points[k] + translations_[b];
  }
}

template class TabulatedDeskewer<1024>;
template class TabulatedDeskewer<128>;

}  // namespace adit::slam
