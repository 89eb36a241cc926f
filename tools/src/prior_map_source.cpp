#include "prior_map_source.hpp"

#include <Eigen/Core>

#include "adit/common/clock.hpp"
#include "adit/common/error.hpp"
#include "adit/slam/prior_map_file.hpp"

namespace adit::tools {

LoadedPrior load_prior(const std::filesystem::path& path, const protocol::PriorInputOptions& options) {
  LoadedPrior out;
  if (std::filesystem::is_directory(path) || path.extension() == ".bin") {
    out.map = slam::read_prior_map(path);
  } else {
    const std::int64_t t0 = monotonic_ns();
    const protocol::PriorInput input = protocol::read_prior_input(path, options);
    std::vector<Eigen::Vector3f> points(input.points.size());
    for (std::size_t i = 0; i < points.size(); ++i) points[i] = Eigen::Vector3f(input.points[i][0], input.points[i][1], input.points[i][2]);
    out.input_points = points.size();
    out.map = slam::prepare_prior_map(points);
    out.prepared_now = true;
    out.prepare_s = 1e-9 * static_cast<double>(monotonic_ns() - t0);
  }
  if (const std::string problem = slam::check_prior_map(out.map); !problem.empty())
    throw InputError(path.string(), "", "not usable as a prior map: " + problem);
  return out;
}

std::size_t prior_map_bytes(const slam::PriorMap& prior) {
  const std::size_t cells = prior.plan.likelihood.size();
  return (prior.points.size() + prior.normals.size()) * sizeof(Eigen::Vector3f) + 3 * cells * sizeof(float);
}

}  // namespace adit::tools
