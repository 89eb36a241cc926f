#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
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

// The left wall may open, where `open(x)`, into a room whose far wall is at y = 5.
Drift drift(const std::function<bool(float)>& open = [](float) { return false; }) {
  Drift d;
  for (float x = 0.013F; x < 30; x += 0.05F) {
    const bool gap = open(x);
    for (float z = -1.0F; z < 3.5F; z += 0.05F) {
      d.points.emplace_back(x, -2.0F, z);
      d.points.emplace_back(x, gap ? 5.0F : 2.2F, z);
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

TEST(CrossSections, AStationOnADoorMovesToWhereTheWallsRunOn) {
  // A door 1 m wide at 9.6-10.6 m: the section at 10 m would measure to the
  // room's far wall. The nearest place whose walls run on for ±0.5 m is 9 m
  // (10.5, 9.5 and 11 m all have the opening within 0.5 m).
  const Drift d = drift([](float x) { return x > 9.6F && x < 10.6F; });
  const std::vector<CrossSection> s = cut_sections(d.points, d.path, SectionOptions{});
  ASSERT_EQ(s.size(), 2u);
  EXPECT_NEAR(s[0].shift_m, -1.0, 1e-9);
  EXPECT_NEAR(s[0].chainage_m, 9.0, 1e-9);
  EXPECT_NEAR(s[0].centre.x(), 9.0, 1e-9);
  EXPECT_TRUE(s[0].walls_regular);
  EXPECT_NEAR(s[0].width_m, 4.2, 1e-3);
  EXPECT_EQ(s[1].shift_m, 0.0);  // 20 m is far from the door
  EXPECT_NEAR(s[1].width_m, 4.2, 1e-3);
  SectionOptions nominal;
  nominal.max_shift_m = 0.0;  // as before stations moved: the room's wall
  EXPECT_NEAR(cut_sections(d.points, d.path, nominal)[0].width_m, 7.0, 1e-3);
}

TEST(CrossSections, AStationAmongPillarsHasNoWidth) {
  // From 7 to 13 m the left wall is pillars 0.3 m wide every metre, the room
  // behind them: of any two places 0.5 m apart one looks between pillars, so
  // no place within 2 m of the station has walls that run on for ±0.5 m.
  const Drift d = drift([](float x) { return x > 7.0F && x < 13.0F && std::fmod(x, 1.0F) > 0.3F; });
  const std::vector<CrossSection> s = cut_sections(d.points, d.path, SectionOptions{});
  ASSERT_EQ(s.size(), 2u);
  EXPECT_FALSE(s[0].walls_regular);
  EXPECT_TRUE(std::isnan(s[0].width_m));
  EXPECT_NEAR(s[0].chainage_m, 10.0, 1e-9);
  EXPECT_NEAR(s[0].height_m, 4.5, 1e-3);  // the height is still given
  const auto file = std::filesystem::temp_directory_path() / "adit_test_section_junction.svg";
  write_section_svg(file, s[0], SectionOptions{});
  std::ifstream in(file);
  const std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(svg.find("width not given"), std::string::npos);
  EXPECT_EQ(svg.find("W "), std::string::npos);
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
