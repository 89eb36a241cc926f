#include "adit/products/outlier_filter.hpp"

#include <pcl/filters/statistical_outlier_removal.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

namespace adit::products {

std::vector<std::uint8_t> statistical_inliers(std::span<const Eigen::Vector3f> points,
                                              std::span<const std::uint8_t> mask, const OutlierOptions& options) {
  std::vector<std::uint8_t> keep(points.size(), 0);
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  std::vector<std::size_t> index;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (mask[i]) {
      cloud->push_back(pcl::PointXYZ(points[i].x(), points[i].y(), points[i].z()));
      index.push_back(i);
    }
  if (cloud->size() <= static_cast<std::size_t>(options.k)) {  // too few to judge: all kept
    for (std::size_t i : index) keep[i] = 1;
    return keep;
  }
  pcl::StatisticalOutlierRemoval<pcl::PointXYZ> sor;
  sor.setInputCloud(cloud);
  sor.setMeanK(options.k);
  sor.setStddevMulThresh(options.stddev_mult);
  pcl::Indices kept;
  sor.filter(kept);
  for (const auto k : kept) keep[index[static_cast<std::size_t>(k)]] = 1;
  return keep;
}

}  // namespace adit::products
