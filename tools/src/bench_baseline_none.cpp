// Builds without PCL have no baseline; `adit bench odometry` says so.
#include "bench_baseline.hpp"

namespace adit::tools {
std::unique_ptr<BaselineOdometry> make_pcl_gicp_baseline(float, float) { return nullptr; }
}  // namespace adit::tools
