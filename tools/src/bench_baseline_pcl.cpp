#include <pcl/filters/voxel_grid.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>

#include "bench_baseline.hpp"

namespace adit::tools {
namespace {

// Scan-to-scan GICP with a constant-velocity initial guess, on voxel-filtered
// clouds: the usual way PCL's GICP is used as LiDAR odometry.
class PclGicpOdometry final : public BaselineOdometry {
 public:
  PclGicpOdometry(float voxel_m, float max_range_m) : voxel_m_(voxel_m), max_range_m_(max_range_m) {
    gicp_.setMaxCorrespondenceDistance(1.0);
    gicp_.setMaximumIterations(30);
    gicp_.setTransformationEpsilon(1e-4);
  }

  Eigen::Isometry3d process(std::span<const Eigen::Vector3f> points) override {
    auto raw = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    raw->reserve(points.size());
    for (const auto& p : points)
      if (p.allFinite() && p.norm() < max_range_m_) raw->emplace_back(p.x(), p.y(), p.z());
    auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    pcl::VoxelGrid<pcl::PointXYZ> grid;
    grid.setLeafSize(voxel_m_, voxel_m_, voxel_m_);
    grid.setInputCloud(raw);
    grid.filter(*cloud);
    if (previous_) {
      gicp_.setInputSource(cloud);
      gicp_.setInputTarget(previous_);
      pcl::PointCloud<pcl::PointXYZ> aligned;
      gicp_.align(aligned, velocity_.matrix().cast<float>());
      const Eigen::Isometry3d delta(gicp_.getFinalTransformation().cast<double>());
      velocity_ = delta;
      pose_ = pose_ * delta;
    }
    previous_ = cloud;
    return pose_;
  }

 private:
  float voxel_m_;
  float max_range_m_;
  pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp_;
  pcl::PointCloud<pcl::PointXYZ>::Ptr previous_;
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d velocity_ = Eigen::Isometry3d::Identity();
};

}  // namespace

std::unique_ptr<BaselineOdometry> make_pcl_gicp_baseline(float voxel_m, float max_range_m) {
  return std::make_unique<PclGicpOdometry>(voxel_m, max_range_m);
}

}  // namespace adit::tools
