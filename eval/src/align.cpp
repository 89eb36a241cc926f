#include "adit/eval/align.hpp"

#include <Eigen/SVD>

namespace adit::eval {

slam::Pose Similarity::apply(const slam::Pose& pose) const {
  slam::Pose out = slam::Pose::Identity();
  out.linear() = rotation * pose.linear();
  out.translation() = apply(Eigen::Vector3d(pose.translation()));
  return out;
}

std::optional<Similarity> umeyama_fit(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to, bool with_scale) {
  const Eigen::Index n = from.cols();
  if (n < 3 || to.cols() != n) return std::nullopt;
  const Eigen::Vector3d mean_from = from.rowwise().mean();  // mu_x, eq. 34
  const Eigen::Vector3d mean_to = to.rowwise().mean();      // mu_y, eq. 35
  const Eigen::Matrix3Xd x = from.colwise() - mean_from;
  const Eigen::Matrix3Xd y = to.colwise() - mean_to;
  const double variance_from = x.squaredNorm() / static_cast<double>(n);          // sigma_x^2, eq. 36
  const Eigen::Matrix3d covariance = y * x.transpose() / static_cast<double>(n);  // Sigma_xy, eq. 38

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  // Rotation is determined only if rank(Sigma_xy) >= 2. The ratio tolerates
  // survey noise: 1e-6 in variance is 1 mm of spread per metre off the line.
  if (!(d(0) > 0.0) || d(1) <= 1e-6 * d(0) || !(variance_from > 0.0)) return std::nullopt;

  Eigen::Vector3d s = Eigen::Vector3d::Ones();  // S, eq. 39: reflect if det(U)det(V) < 0
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) s(2) = -1.0;

  Similarity out;
  out.rotation = svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();  // eq. 40
  out.scale = with_scale ? d.dot(s) / variance_from : 1.0;                    // eq. 42
  out.translation = mean_to - out.scale * out.rotation * mean_from;           // eq. 41
  return out;
}

std::optional<Alignment> parse_alignment(std::string_view name) {
  if (name == "none") return Alignment::none;
  if (name == "origin") return Alignment::origin;
  if (name == "se3") return Alignment::se3;
  if (name == "sim3") return Alignment::sim3;
  return std::nullopt;
}

std::string_view alignment_name(Alignment alignment) {
  switch (alignment) {
    case Alignment::none: return "none";
    case Alignment::origin: return "origin";
    case Alignment::se3: return "se3";
    case Alignment::sim3: return "sim3";
  }
  return "?";
}

std::optional<Similarity> align_trajectory(std::span<const slam::Pose> ref, std::span<const slam::Pose> est, Alignment alignment) {
  if (alignment == Alignment::none) return Similarity{};
  if (ref.empty() || ref.size() != est.size()) return std::nullopt;
  if (alignment == Alignment::origin) {
    const slam::Pose t = ref.front() * est.front().inverse();
    return Similarity{t.linear(), t.translation(), 1.0};
  }
  Eigen::Matrix3Xd from(3, static_cast<Eigen::Index>(est.size()));
  Eigen::Matrix3Xd to(3, static_cast<Eigen::Index>(ref.size()));
  for (std::size_t i = 0; i < est.size(); ++i) {
    from.col(static_cast<Eigen::Index>(i)) = est[i].translation();
    to.col(static_cast<Eigen::Index>(i)) = ref[i].translation();
  }
  return umeyama_fit(from, to, alignment == Alignment::sim3);
}

}  // namespace adit::eval
