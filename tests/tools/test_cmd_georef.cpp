// `adit georef` end to end on a session folder: site coordinates at
// E 512 345 / N 7 012 345 (millimetres kept), the residual table, the CRS in
// the LAS file (PROJ's WKT for EPSG:32633), and bad control files refused with
// file and line, exit status 2 and nothing written.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "adit/protocol/map_export.hpp"
#include "adit/protocol/map_import.hpp"
#include "adit/slam/tum.hpp"
#include "run_program.hpp"
#include "shared_data.hpp"

namespace adit {
namespace {

// map -> site: turned 37° about up, far from the origin.
Eigen::Vector3d to_site(const Eigen::Vector3d& p) {
  const double a = 37.0 * std::numbers::pi / 180.0;
  return {512345.678 + std::cos(a) * p.x() - std::sin(a) * p.y(), 7012345.432 + std::sin(a) * p.x() + std::cos(a) * p.y(),
          1234.5 + p.z()};
}

const std::vector<Eigen::Vector3d> kTargets{{3.0, 2.1, 1.2},  {14.0, -2.0, 1.6}, {27.0, 2.2, 0.9},
                                            {38.5, -1.9, 1.4}, {44.0, 9.0, 1.1}, {47.8, 22.0, 1.7}};

struct Session {
  std::filesystem::path dir;
  explicit Session(const std::string& name) : dir(test::binary_dir() / fmt::format("georef-{}-{}", name, ::getpid())) {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    slam::Trajectory path;
    for (int k = 0; k <= 40; ++k) {
      slam::Pose p = slam::Pose::Identity();
      p.translation() = Eigen::Vector3d(1.2 * k, 0.1 * k, 0.0);
      path.push_back(1000.0 + k, p);
    }
    slam::write_tum(dir / "map_trajectory.tum", path);
    std::vector<protocol::MapPoint> points;
    for (int i = 0; i < 500; ++i) points.push_back({0.1 * i, 0.05 * i, 0.5, 20.0F, 1005.0});
    protocol::write_map(dir / "map.las", protocol::MapFormat::las, points);
    std::ofstream t(dir / "targets.csv");
    t << "id,x,y,z,sigma_m\n";
    for (std::size_t i = 0; i < kTargets.size(); ++i)
      t << fmt::format("{},{:.4f},{:.4f},{:.4f},0.003\n", i + 1, kTargets[i].x(), kTargets[i].y(), kTargets[i].z());
  }
  ~Session() { std::filesystem::remove_all(dir); }
  // Control points on targets `which` (1-based), optionally E/N swapped.
  std::filesystem::path control(const std::string& name, const std::vector<int>& which, bool swap = false,
                                const std::string& extra = "") const {
    const auto file = dir / name;
    std::ofstream c(file);
    for (const int k : which) {
      Eigen::Vector3d s = to_site(kTargets[static_cast<std::size_t>(k - 1)]);
      if (swap) std::swap(s.x(), s.y());
      c << fmt::format("CP{},{:.4f},{:.4f},{:.4f}\n", k, s.x(), s.y(), s.z());
    }
    c << extra;
    return file;
  }
};

std::string bytes_of(const std::filesystem::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(CmdGeoref, WritesTheMapAndPathInSiteCoordinatesWithTheCrs) {
  const Session s("ok");
  const auto control = s.control("control.csv", {1, 3, 5, 6});
  const auto out = s.dir / "site";
  const test::CommandRun r = test::run_adit(fmt::format("georef {} --control {} --targets {} --epsg 32633 --ply --out {}",
                                                        s.dir.string(), control.string(), (s.dir / "targets.csv").string(),
                                                        out.string()));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("4 of 4 matched to targets by geometry; rigid fit on 4"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("CP5          5"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("FLAGGED"), std::string::npos) << r.output;
  // The map's points, in site coordinates to the millimetre.
  const auto site = protocol::read_map(out / "map.las");
  ASSERT_EQ(site.size(), 500U);
  for (const int i : {0, 123, 499}) {
    const Eigen::Vector3d want = to_site({0.1 * i, 0.05 * i, 0.5});
    EXPECT_NEAR(site[static_cast<std::size_t>(i)].x, want.x(), 0.001) << i;
    EXPECT_NEAR(site[static_cast<std::size_t>(i)].y, want.y(), 0.001) << i;
    EXPECT_NEAR(site[static_cast<std::size_t>(i)].z, want.z(), 0.001) << i;
  }
  const auto ply = protocol::read_map(out / "map.ply");
  EXPECT_NEAR(ply[499].x, to_site({49.9, 24.95, 0.5}).x(), 0.001);  // a float keeps 3 cm steps here
  const std::string las = bytes_of(out / "map.las");
  EXPECT_NE(las.find("LASF_Projection"), std::string::npos);
  EXPECT_NE(las.find("WGS 84 / UTM zone 33N"), std::string::npos);
  const slam::Trajectory path = slam::read_tum(out / "map_trajectory.tum");
  ASSERT_EQ(path.size(), 41U);
  EXPECT_LT((path.poses[40].translation() - to_site({48.0, 4.0, 0.0})).norm(), 0.001);
  const nlohmann::json j = nlohmann::json::parse(bytes_of(out / "georef.json"));
  EXPECT_EQ(j["matched_by"], "geometry");
  EXPECT_EQ(j["epsg"], 32633);
  EXPECT_LT(j["rms_m"].get<double>(), 0.001);
}

TEST(CmdGeoref, BadControlFilesAreRefusedAndNothingIsWritten) {
  const Session s("bad");
  const auto out = s.dir / "site";
  const auto run = [&](const std::filesystem::path& control, const std::string& more = "") {
    return test::run_adit(fmt::format("georef {} --control {} --targets {} --out {} {}", s.dir.string(), control.string(),
                                      (s.dir / "targets.csv").string(), out.string(), more));
  };
  const auto expect_refused = [&](const test::CommandRun& r, const std::string& says) {
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(says), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << says;
  };
  const std::string name = (s.dir / "dup.csv").string();
  expect_refused(run(s.control("dup.csv", {1, 3, 5}, false, "CP3,1,2,3\n")), name + ":4");
  expect_refused(run(s.control("dup.csv", {1, 3, 5}, false, "CP3,1,2,3\n")), "'CP3' appears twice (also line 2)");
  expect_refused(run(s.control("swapped.csv", {1, 3, 5, 6}, true)), "E and N look swapped");
  expect_refused(run(s.control("two.csv", {1, 6})), "2 control points matched a target by geometry");
  expect_refused(run(s.control("ok.csv", {1, 3, 5, 6}), "--epsg 999999"), "EPSG:999999 is not a coordinate reference system");
  expect_refused(run(s.control("ok.csv", {1, 3, 5, 6}), "--match id"), "'CP1' is not a target id");
  // Feet: the file in feet read as metres, then stated.
  std::ofstream(s.dir / "feet.csv") << [&] {
    std::string text;
    for (const int k : {1, 3, 5, 6}) {
      const Eigen::Vector3d p = to_site(kTargets[static_cast<std::size_t>(k - 1)]) / 0.3048;
      text += fmt::format("CP{},{:.4f},{:.4f},{:.4f}\n", k, p.x(), p.y(), p.z());
    }
    return text;
  }();
  expect_refused(run(s.dir / "feet.csv"), "the file looks to be in feet; say --units ft");
  const test::CommandRun feet = run(s.dir / "feet.csv", "--units ft");
  EXPECT_EQ(feet.status, 0) << feet.output;
}

}  // namespace
}  // namespace adit
