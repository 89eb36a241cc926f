#include "adit/sim/truth.hpp"

#include "adit/common/error.hpp"
#include "adit/slam/tum.hpp"

namespace adit::sim {

void write_tum(const std::filesystem::path& file, const BodyTrack& body, const Eigen::Isometry3d& frame,
               std::int64_t start_time_ns) {
  slam::TumWriter out(file);
  const auto& samples = body.samples();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = samples[i].position;
    pose.linear() = samples[i].orientation.toRotationMatrix();
    const std::int64_t ns = start_time_ns + static_cast<std::int64_t>(i) * static_cast<std::int64_t>(1e9 / BodyTrack::kRate);
    out.write(ns, pose * frame);
  }
  if (!out.flush()) throw InputError(file.string(), "", "could not write the trajectory");
}

}  // namespace adit::sim
