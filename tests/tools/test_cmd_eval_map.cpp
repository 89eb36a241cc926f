// End-to-end: `adit eval map` on a tiny scene mesh and tiny maps written here.

#include <cmath>
#include <cstdint>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "adit/protocol/map_export.hpp"
#include "run_adit.hpp"
#include "temp_file.hpp"

namespace adit {
namespace {

using protocol::MapFormat;
using protocol::MapPoint;
using test::adit_eval;
using test::EvalRun;
using test::q;
using test::TempFile;
using namespace std::string_literals;

template <typename T>
void put(std::string& bytes, T v) {
  bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// A 10 x 10 m floor (z = 0) and a wall at x = 10, two triangles each, in the
// layout of adit sim's scene.ply.
std::string scene_bytes() {
  std::string b =
      "ply\nformat binary_little_endian 1.0\ncomment adit sim scene\nelement vertex 8\nproperty float x\n"
      "property float y\nproperty float z\nelement face 4\nproperty list uchar uint vertex_indices\n"
      "property uchar reflectivity\nend_header\n";
  const std::vector<std::array<float, 3>> vertices{{0, 0, 0},  {10, 0, 0},  {10, 10, 0}, {0, 10, 0},
                                                   {10, 0, 0}, {10, 10, 0}, {10, 10, 5}, {10, 0, 5}};
  for (const auto& v : vertices)
    for (float c : v) put(b, c);
  for (const auto& t : {std::array<std::uint32_t, 3>{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}}) {
    put<std::uint8_t>(b, 3);
    for (auto i : t) put(b, i);
    put<std::uint8_t>(b, 50);
  }
  return b;
}

// World points at known distances from the scene: 0.0095 .. 0.0895 m above
// the floor (off the 0.05 threshold by more than float32 rounding), 0.02 m in
// front of the wall, one 3 m above the floor's middle (beyond a 1 m cap).
// Sorted: .0095 .0195 .02 .0295 .0395 .0495 | .0595 .0695 .0795 .0895 inf.
std::vector<Eigen::Vector3d> world_points() {
  std::vector<Eigen::Vector3d> p;
  for (int i = 1; i <= 9; ++i) p.emplace_back(0.5 + i, 0.5 * i, 0.01 * i - 0.0005);
  p.emplace_back(9.98, 5.0, 2.0);
  p.emplace_back(5.0, 5.0, 3.0);
  return p;
}

std::vector<MapPoint> map_points(const Eigen::Isometry3d& map_from_world) {
  std::vector<MapPoint> out;
  for (const auto& w : world_points()) {
    const Eigen::Vector3d m = map_from_world * w;
    out.push_back({m.x(), m.y(), m.z(), 10.0f, 0.0});
  }
  return out;
}

class AditEvalMap : public ::testing::Test {
 protected:
  TempFile scene{scene_bytes(), ".ply"};

  // Writes the points, in the frame `map_from_world`, in the format of f's suffix.
  static void fill(const TempFile& f, const Eigen::Isometry3d& map_from_world) {
    protocol::write_map(f.path(), *protocol::parse_map_format(f.path().extension().string().substr(1)),
                        map_points(map_from_world));
  }
  static nlohmann::json json_of(const EvalRun& run) {
    EXPECT_EQ(run.status, 0) << run.output;
    return run.status == 0 ? nlohmann::json::parse(run.output) : nlohmann::json::object();
  }
};

TEST_F(AditEvalMap, KnownDistancesInTheSceneFrame) {
  const TempFile map("", ".ply");
  fill(map, Eigen::Isometry3d::Identity());
  const auto j = json_of(adit_eval("map --map "s + q(map) + " --scene " + q(scene) + " --json"));
  EXPECT_EQ(j["points"].get<int>(), 11);
  EXPECT_NEAR(j["fraction_within"].get<double>(), 6.0 / 11.0, 1e-12);
  EXPECT_NEAR(j["median_m"].get<double>(), 0.0495, 1e-6);  // float32 coordinates
  EXPECT_TRUE(j["p95_m"].is_null()) << "ceil(0.95 * 11) = 11th smallest is beyond the cap";
  EXPECT_NEAR(j["mean_m"].get<double>(), 0.4655 / 10.0, 1e-6);
  EXPECT_EQ(j["beyond_cap"].get<int>(), 1);
  // A larger cap measures the last point too: 3 m.
  const auto wide = json_of(adit_eval("map --map "s + q(map) + " --scene " + q(scene) + " --cap 5 --json"));
  EXPECT_EQ(wide["beyond_cap"].get<int>(), 0);
  EXPECT_NEAR(wide["p95_m"].get<double>(), 3.0, 1e-6);
  // The table says the same.
  const EvalRun table = adit_eval("map --map "s + q(map) + " --scene " + q(scene) + " --within 0.025");
  ASSERT_EQ(table.status, 0) << table.output;
  EXPECT_NE(table.output.find("27.27 % (3 points)"), std::string::npos) << table.output;
  EXPECT_NE(table.output.find("> 1 m (cap)"), std::string::npos) << table.output;
}

TEST_F(AditEvalMap, EveryMapFormatGivesTheSameFigures) {
  for (const char* suffix : {".ply", ".pcd", ".las"}) {
    SCOPED_TRACE(suffix);
    const TempFile map("", suffix);
    fill(map, Eigen::Isometry3d::Identity());
    const auto j = json_of(adit_eval("map --map "s + q(map) + " --scene " + q(scene) + " --json"));
    EXPECT_EQ(j["beyond_cap"].get<int>(), 1);
    EXPECT_NEAR(j["median_m"].get<double>(), 0.0495, 1e-3);  // LAS: 1 mm integers
    EXPECT_NEAR(j["mean_m"].get<double>(), 0.04655, 1e-3);
  }
}

// The map is in the estimate's frame; the reference puts the body at t0 =
// 100 s (interpolated between 99 s and 101 s) at (2, 3, 0) facing +y, where
// the estimate says (0.5, 0, 0) facing +x.
TEST_F(AditEvalMap, PlacedByTheTrajectoriesFirstPose) {
  const TempFile ref(
      "99.0 1 3 0 0 0 0.7071067811865476 0.7071067811865476\n"
      "101.0 3 3 0 0 0 0.7071067811865476 0.7071067811865476\n");
  const TempFile est("100.0 0.5 0 0 0 0 0 1\n100.1 0.6 0 0 0 0 0 1\n");
  Eigen::Isometry3d ref_t0 = Eigen::Isometry3d::Identity();
  ref_t0.translation() = Eigen::Vector3d(2, 3, 0);
  ref_t0.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Isometry3d est_t0 = Eigen::Isometry3d::Identity();
  est_t0.translation() = Eigen::Vector3d(0.5, 0, 0);
  const Eigen::Isometry3d map_from_world = est_t0 * ref_t0.inverse();
  const TempFile map("", ".ply");
  fill(map, map_from_world);

  const auto placed = json_of(
      adit_eval("map --map "s + q(map) + " --scene " + q(scene) + " --ref " + q(ref) + " --est " + q(est) + " --json"));
  EXPECT_NEAR(placed["fraction_within"].get<double>(), 6.0 / 11.0, 1e-12);
  EXPECT_NEAR(placed["median_m"].get<double>(), 0.0495, 1e-5);
  EXPECT_EQ(placed["beyond_cap"].get<int>(), 1);
  // Unplaced, the same map misses the scene.
  const auto unplaced = json_of(adit_eval("map --map "s + q(map) + " --scene " + q(scene) + " --json"));
  EXPECT_LT(unplaced["fraction_within"].get<double>(), 0.3);

  // t0 outside the reference is an input error naming the reference.
  const TempFile late("101.5 0.5 0 0 0 0 0 1\n102.5 0.6 0 0 0 0 0 1\n");
  const EvalRun outside =
      adit_eval("map --map "s + q(map) + " --scene " + q(scene) + " --ref " + q(ref) + " --est " + q(late));
  EXPECT_EQ(outside.status, 2) << outside.output;
  EXPECT_NE(outside.output.find(ref.path().string()), std::string::npos) << outside.output;
  EXPECT_NE(outside.output.find("outside"), std::string::npos) << outside.output;
  // --ref without --est is refused.
  EXPECT_NE(adit_eval("map --map "s + q(map) + " --scene " + q(scene) + " --ref " + q(ref)).status, 0);
}

// A reference path (level body) and the estimate of it in the map frame
// `map_from_world`, its first attitude off by `first_roll_rad` more.
std::pair<std::string, std::string> path_texts(const Eigen::Isometry3d& map_from_world, double first_roll_rad) {
  std::string ref_text, est_text;
  const std::vector<Eigen::Vector3d> path{{1, 1, 0.5}, {3, 1, 0.5}, {5, 1, 0.6}, {5, 3, 0.5}, {5, 5, 0.4}, {3, 5, 0.5}};
  for (std::size_t i = 0; i < path.size(); ++i) {
    const Eigen::Vector3d m = map_from_world * path[i];
    Eigen::Quaterniond qm(map_from_world.linear());
    if (i == 0) qm = qm * Eigen::AngleAxisd(first_roll_rad, Eigen::Vector3d::UnitX());
    const double t = 100.0 + 0.1 * static_cast<double>(i);
    ref_text += fmt::format("{:.1f} {} {} {} 0 0 0 1\n", t, path[i].x(), path[i].y(), path[i].z());
    est_text += fmt::format("{:.1f} {:.9f} {:.9f} {:.9f} {:.12f} {:.12f} {:.12f} {:.12f}\n", t, m.x(), m.y(), m.z(), qm.x(),
                            qm.y(), qm.z(), qm.w());
  }
  return {ref_text, est_text};
}

// --align se3 places the map by the rigid fit of all the estimate's positions
// to the reference's, as a surveyor fits a map to control points: here the
// estimate's first attitude is 3° off (the map itself is right), which
// tilts the map placed by its first pose but not the fitted one.
TEST_F(AditEvalMap, PlacedByARigidFitOfTheTrajectories) {
  Eigen::Isometry3d map_from_world = Eigen::Isometry3d::Identity();
  map_from_world.translation() = Eigen::Vector3d(-1.0, 2.0, 0.3);
  map_from_world.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const auto [ref_text, est_text] = path_texts(map_from_world, 3.0 * M_PI / 180);
  const TempFile ref(ref_text), est(est_text), map("", ".ply");
  fill(map, map_from_world);
  const std::string placed_by = "map --map "s + q(map) + " --scene " + q(scene) + " --ref " + q(ref) + " --est " + q(est);
  const auto fitted = json_of(adit_eval(placed_by + " --align se3 --json"));
  EXPECT_NEAR(fitted["fraction_within"].get<double>(), 6.0 / 11.0, 1e-9);
  EXPECT_NEAR(fitted["median_m"].get<double>(), 0.0495, 1e-5);
  EXPECT_EQ(fitted["placement"], "se3");
  const auto by_origin = json_of(adit_eval(placed_by + " --json"));
  EXPECT_EQ(by_origin["placement"], "origin");
  EXPECT_GT(std::abs(by_origin["median_m"].get<double>() - 0.0495), 0.005) << "the first pose's 3° tilts the map";
  // The map's own z is vertical (only turned about it): the fit says so; the
  // first pose's 3° makes the placement tilt it by as much.
  EXPECT_NEAR(fitted["map_tilt_deg"].get<double>(), 0.0, 1e-4);
  EXPECT_NEAR(by_origin["map_tilt_deg"].get<double>(), 3.0, 1e-4);

  // Poses on one line fix no rotation: an input error naming the estimate.
  const TempFile line("100.0 0 0 0 0 0 0 1\n100.1 1 0 0 0 0 0 1\n100.2 2 0 0 0 0 0 1\n");
  const EvalRun degenerate = adit_eval("map --map "s + q(map) + " --scene " + q(scene) + " --ref " + q(ref) +
                                       " --est " + q(line) + " --align se3");
  EXPECT_EQ(degenerate.status, 2) << degenerate.output;
  EXPECT_NE(degenerate.output.find(line.path().string()), std::string::npos) << degenerate.output;
}

// --align heading keeps the map's own vertical: a first attitude 3° off
// costs nothing (the map is level); a map whose z is 3° off plumb (its first
// pose's, as aditd's) keeps its tilt and is scored with it, where the origin
// placement hands it the reference's first attitude.
TEST_F(AditEvalMap, PlacedByTheFirstPoseTurnedAboutTheVerticalOnly) {
  Eigen::Isometry3d level = Eigen::Isometry3d::Identity();
  level.translation() = Eigen::Vector3d(-1.0, 2.0, 0.3);
  level.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Isometry3d tilted = level;
  tilted.linear() = Eigen::AngleAxisd(3.0 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix() * level.linear();
  for (const bool map_tilted : {false, true}) {
    const Eigen::Isometry3d map_from_world = map_tilted ? tilted : level;
    const auto [ref_text, est_text] = path_texts(map_from_world, map_tilted ? 0.0 : 3.0 * M_PI / 180);
    const TempFile ref(ref_text), est(est_text), map("", ".ply");
    fill(map, map_from_world);
    const std::string placed_by = "map --map "s + q(map) + " --scene " + q(scene) + " --ref " + q(ref) + " --est " + q(est);
    const auto heading = json_of(adit_eval(placed_by + " --align heading --json"));
    const auto origin = json_of(adit_eval(placed_by + " --json"));
    EXPECT_EQ(heading["placement"], "heading");
    EXPECT_NEAR(heading["map_tilt_deg"].get<double>(), 0.0, 1e-6);
    if (!map_tilted) {
      EXPECT_NEAR(heading["fraction_within"].get<double>(), 6.0 / 11.0, 1e-9);
      EXPECT_NEAR(heading["median_m"].get<double>(), 0.0495, 1e-5);
    } else {
      EXPECT_NEAR(origin["fraction_within"].get<double>(), 6.0 / 11.0, 1e-9);  // given the true first attitude
      EXPECT_NEAR(origin["map_tilt_deg"].get<double>(), 3.0, 1e-4);
      EXPECT_LT(heading["fraction_within"].get<double>(), 5.0 / 11.0) << "the map's own 3° is scored";
    }
  }
  const TempFile map("", ".ply");
  fill(map, level);
  EXPECT_NE(adit_eval("map --map "s + q(map) + " --scene " + q(scene) + " --align heading").status, 0)
      << "heading needs --ref and --est";
}

TEST_F(AditEvalMap, BadFilesAreNamed) {
  const TempFile map("", ".ply");
  fill(map, Eigen::Isometry3d::Identity());
  std::filesystem::resize_file(map.path(), std::filesystem::file_size(map.path()) - 5);
  const EvalRun cut = adit_eval("map --map "s + q(map) + " --scene " + q(scene));
  EXPECT_EQ(cut.status, 2) << cut.output;
  EXPECT_NE(cut.output.find(map.path().string()), std::string::npos) << cut.output;
  EXPECT_NE(cut.output.find("truncated"), std::string::npos) << cut.output;

  const std::string good = scene_bytes();
  const TempFile bad_scene(good.substr(0, good.size() - 4), ".ply");
  const TempFile whole("", ".pcd");
  fill(whole, Eigen::Isometry3d::Identity());
  const EvalRun scene_cut = adit_eval("map --map "s + q(whole) + " --scene " + q(bad_scene));
  EXPECT_EQ(scene_cut.status, 2) << scene_cut.output;
  EXPECT_NE(scene_cut.output.find(bad_scene.path().string()), std::string::npos) << scene_cut.output;

  const TempFile xyz("1 2 3\n", ".xyz");
  const EvalRun unknown = adit_eval("map --map "s + q(xyz) + " --scene " + q(scene));
  EXPECT_EQ(unknown.status, 2) << unknown.output;
  EXPECT_NE(unknown.output.find(xyz.path().string()), std::string::npos) << unknown.output;
}

}  // namespace
}  // namespace adit
