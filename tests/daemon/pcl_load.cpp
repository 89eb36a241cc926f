#include "pcl_load.hpp"

#ifdef ADIT_TEST_WITH_PCL
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>
#endif

namespace adit::test {

#ifdef ADIT_TEST_WITH_PCL
bool have_pcl() { return true; }

std::optional<std::size_t> pcl_point_count(const std::filesystem::path& file, std::string& error) {
  pcl::PointCloud<pcl::PointXYZI> cloud;
  const int status = file.extension() == ".pcd" ? pcl::io::loadPCDFile(file.string(), cloud)
                                                : pcl::io::loadPLYFile(file.string(), cloud);
  if (status < 0) {
    error = "PCL could not load " + file.string();
    return std::nullopt;
  }
  return cloud.size();
}
#else
bool have_pcl() { return false; }
std::optional<std::size_t> pcl_point_count(const std::filesystem::path&, std::string& error) {
  error = "built without PCL";
  return std::nullopt;
}
#endif

}  // namespace adit::test
