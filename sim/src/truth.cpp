#include "adit/sim/truth.hpp"

#include <fstream>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::sim {

void write_tum(const std::filesystem::path& file, const Trajectory& body, const Eigen::Isometry3d& frame,
               std::int64_t start_time_ns) {
  std::ofstream out(file, std::ios::trunc);
  const auto& samples = body.samples();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = samples[i].position;
    pose.linear() = samples[i].orientation.toRotationMatrix();
    pose = pose * frame;
    const Eigen::Quaterniond q(pose.linear());
    // Whole seconds and nanoseconds apart: doubles lose µs at Unix times.
    const std::int64_t ns = start_time_ns + static_cast<std::int64_t>(i) * static_cast<std::int64_t>(1e9 / Trajectory::kRate);
    out << fmt::format("{}.{:09d} {:.6f} {:.6f} {:.6f} {:.9f} {:.9f} {:.9f} {:.9f}\n", ns / 1'000'000'000,
                       ns % 1'000'000'000, pose.translation().x(), pose.translation().y(), pose.translation().z(), q.x(),
                       q.y(), q.z(), q.w());
  }
  if (!out) throw InputError(file.string(), "", "could not write the trajectory");
}

}  // namespace adit::sim
