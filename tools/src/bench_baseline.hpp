#pragma once
// The baseline odometry `adit bench odometry` compares against, in the same
// run on the same scans: scan-to-scan registration with PCL's Generalized-ICP
// (Segal, Haehnel & Thrun, RSS 2009), a widely used reference. Built only when
// PCL is found (ADIT_HAVE_PCL); its headers stay in bench_baseline_pcl.cpp.

#include <memory>
#include <span>

#include <Eigen/Geometry>

namespace adit::tools {

class BaselineOdometry {
 public:
  virtual ~BaselineOdometry() = default;
  // Registers the scan against the previous one; returns the pose in the first scan's frame.
  virtual Eigen::Isometry3d process(std::span<const Eigen::Vector3f> points) = 0;
};

// nullptr when this build has no PCL.
std::unique_ptr<BaselineOdometry> make_pcl_gicp_baseline(float voxel_m, float max_range_m);

}  // namespace adit::tools
