#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

#include "adit/products/cross_sections.hpp"
#include "adit/products/raster_image.hpp"
#include "adit/products/top_view.hpp"

namespace adit::products {
namespace {

// A straight drift along x, 4.20 m wide (walls at y = -2.0 and +2.2), floor
// at z = -1, roof at z = 3.5, every 5 cm; the sensor at z = 0 along y = 0.
struct Drift {
  std::vector<Eigen::Vector3f> points;
  slam::Trajectory path;
};

Drift drift() {
  Drift d;
  for (float x = 0.013F; x < 30; x += 0.05F) {
    for (float z = -1.0F; z < 3.5F; z += 0.05F) {
      d.points.emplace_back(x, -2.0F, z);
      d.points.emplace_back(x, 2.2F, z);
    }
    for (float y = -1.987F; y < 2.2F; y += 0.05F) {
      d.points.emplace_back(x, y, -1.0F);
      d.points.emplace_back(x, y, 3.5F);
    }
  }
  for (int k = 0; k <= 300; ++k) {
    slam::Pose p = slam::Pose::Identity();
    p.translation() = Eigen::Vector3d(0.1 * k, 0.0, 0.0);
    d.path.push_back(0.1 * k, p);
  }
  return d;
}

TEST(CrossSections, WidthAndHeightOfAStraightDrift) {
  const Drift d = drift();
  const std::vector<CrossSection> s = cut_sections(d.points, d.path, SectionOptions{});
  ASSERT_EQ(s.size(), 2u);  // at 10 and 20 m (30 m is the end)
  for (const CrossSection& c : s) {
    EXPECT_NEAR(c.width_m, 4.2, 1e-3);
    EXPECT_NEAR(c.height_m, 4.5, 1e-3);
    EXPECT_NEAR(c.left_u, 2.2, 1e-3);  // left of a path going +x is +y
    EXPECT_GT(c.profile.size(), 100u);
  }
  EXPECT_NEAR(s[1].chainage_m, 20.0, 1e-9);
  const auto dir = std::filesystem::temp_directory_path() / "adit_test_sections";
  std::filesystem::create_directories(dir);
  EXPECT_GT(write_section_svg(dir / "s.svg", s[0], SectionOptions{}), 0u);
  std::ifstream in(dir / "s.svg");
  const std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(svg.find("W 4.20 m"), std::string::npos);
  EXPECT_NE(svg.find("H 4.50 m"), std::string::npos);
  write_sections_csv(dir / "s.csv", s);
  std::ifstream csv(dir / "s.csv");
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  EXPECT_EQ(header, "id,chainage_m,x,y,z,across_x,across_y,floor_z,roof_z,width_m,height_m");
  EXPECT_NE(row.find(",4.2000,4.5000"), std::string::npos) << row;
}

TEST(TopView, PngWithThePathAndAScaleBar) {
  const Drift d = drift();
  const auto file = std::filesystem::temp_directory_path() / "adit_test_top_view.png";
  const TopViewReport r = write_top_view(file, d.points, GroundModel(), d.path, {}, TopViewOptions{});
  EXPECT_EQ(r.bytes, std::filesystem::file_size(file));
  EXPECT_NEAR(r.pixel_m, 0.05, 1e-12);
  EXPECT_EQ(r.scale_bar_m, 5.0);  // a fifth of ~30 m, rounded down to 1-2-5
  std::ifstream in(file, std::ios::binary);
  char magic[8];
  in.read(magic, 8);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
}

TEST(TopView, NiceLengths) {
  EXPECT_EQ(nice_length(7.3), 5.0);
  EXPECT_EQ(nice_length(19.0), 10.0);
  EXPECT_EQ(nice_length(0.3), 0.2);
  EXPECT_EQ(nice_length(0.0), 0.0);
  EXPECT_EQ(viridis(0.0)[0], 68);
  EXPECT_EQ(viridis(1.0)[2], 37);
}

}  // namespace
}  // namespace adit::products
