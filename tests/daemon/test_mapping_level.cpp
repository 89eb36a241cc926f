// The mapping stage keeping gravity's level (MappingStage::write_level_to,
// decision 060): from the odometry's first up, on the disk for a recovery and
// in RAM for the status; the last up at the end; an up it cannot level by
// ends the levelling, leaving the session in the odometry frame. And the
// map's refinement of the odometry, which frame_t places the poses by.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "adit/daemon/mapping_stage.hpp"
#include "adit/daemon/session_frame.hpp"
#include "adit/slam/levelling.hpp"
#include "adit/slam/map_refiner.hpp"
#include "map_slots.hpp"
#include "temp_file.hpp"

namespace adit::daemon {
namespace {

using namespace std::chrono_literals;

// Gravity's up seen in an odometry frame tilted by `deg` about x.
Eigen::Vector3d up_tilted(double deg) {
  return Eigen::AngleAxisd(deg * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix() * Eigen::Vector3d::UnitZ();
}

bool same_turn(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle() < 1e-9;
}

// A still sensor before a wall; each scan with its up (none: nullopt).
class LevelRun {
 public:
  explicit LevelRun(const std::filesystem::path& file)
      : scans_(4, Overflow::wait, [] { return MapSlot{}; }),
        stage_(config(), slam::OdometryConfig{}, scans_, 100, {}, stats_, stop_) {
    stage_.write_level_to(file);
    stage_.start();
  }
  void push(double t_s, const std::optional<Eigen::Vector3d>& up) {
    MapSlot* slot = scans_.acquire_or_wait([] { return true; });
    ASSERT_NE(slot, nullptr);
    slot->stamp_ns = static_cast<std::int64_t>(t_s * 1e9);
    slot->valid = true;
    slot->points.assign(10, Eigen::Vector3f(5.0F, 0.0F, 0.0F));
    slot->times_s.assign(10, 0.0F);
    slot->intensities.assign(10, 1.0F);
    slot->up = up;
    scans_.publish(slot);
  }
  void end() {
    scans_.close();
    stage_.join();
  }
  const MappingStage& stage() const { return stage_; }

 private:
  static config::Config config() {
    config::Config c;
    c.map.refine = false;
    c.grid.enabled = false;
    return c;
  }
  std::atomic<bool> stop_{false};
  PipelineStats stats_;
  Handoff<MapSlot> scans_;
  MappingStage stage_;
};

TEST(MappingLevel, TheOdometrysUpIsKeptFromTheFirstAndTheLastAtTheEnd) {
  const test::TempFolder dir;
  const std::filesystem::path file = dir.path() / "level_frame.json";
  LevelRun run(file);
  EXPECT_FALSE(run.stage().level().has_value());
  run.push(1.0, std::nullopt);  // before the odometry had an up
  run.push(1.1, up_tilted(0.5));
  run.push(1.2, up_tilted(0.5));  // the stage maps a scan once the next one came: 1.1 s is mapped now
  for (int i = 0; i < 300 && !std::filesystem::exists(file); ++i) std::this_thread::sleep_for(10ms);
  const std::optional<Eigen::Isometry3d> first = read_level_frame(file);
  ASSERT_TRUE(first.has_value()) << "the first up was not kept on the disk";
  EXPECT_TRUE(same_turn(*first, slam::level_from_up(up_tilted(0.5))));
  // The status reads it from another thread (ThreadSanitizer runs this test).
  std::optional<Eigen::Isometry3d> seen;
  for (int i = 0; i < 300 && !seen; ++i) {
    seen = run.stage().level();
    if (!seen) std::this_thread::sleep_for(10ms);
  }
  ASSERT_TRUE(seen.has_value());
  EXPECT_TRUE(same_turn(*seen, *first));
  // The filter's gravity moves on; the up at the end is what the exports get.
  run.push(2.0, up_tilted(0.3));
  run.push(5.0, up_tilted(0.2));   // kept: 2 s on and turned
  run.push(5.5, up_tilted(0.25));  // not yet (within kLevelPeriodS): kept at the end
  run.push(5.6, std::nullopt);     // a scan without an up changes nothing
  run.end();
  const std::optional<Eigen::Isometry3d> last = read_level_frame(file);
  ASSERT_TRUE(last.has_value());
  EXPECT_TRUE(same_turn(*last, slam::level_from_up(up_tilted(0.25))));
  ASSERT_TRUE(run.stage().level().has_value());
  EXPECT_TRUE(same_turn(*run.stage().level(), *last));
}

TEST(MappingLevel, AnUpThatCannotLevelEndsTheLevellingAndNoFileIsLeft) {
  const test::TempFolder dir;
  const std::filesystem::path file = dir.path() / "level_frame.json";
  LevelRun run(file);
  run.push(1.0, up_tilted(0.5));
  run.push(1.1, up_tilted(0.5));
  run.push(4.0, Eigen::Vector3d(0.0, 0.0, -1.0));  // a sign error: down, not a tilt
  run.push(7.0, up_tilted(0.4));                   // not taken after it
  run.push(7.1, up_tilted(0.4));
  run.end();
  EXPECT_FALSE(std::filesystem::exists(file)) << "the first level kept would leave the exports half levelled";
  EXPECT_FALSE(run.stage().level().has_value());
}

// A still sensor in a room's corner (two walls and the floor, 0.1 m apart)
// whose odometry creeps 2 cm and 1 cm a scan in x and z from the fourth scan;
// the scans from `anchored_from` on come anchored to a prior map. Returns the
// stage's refinement (M·O⁻¹) at the end, the last odometry pose and what a
// MapRefiner given the same scans makes of it.
struct CornerRun {
  Eigen::Isometry3d refinement, odometry, map_pose;
};

CornerRun map_a_creeping_corner(int anchored_from) {
  constexpr std::size_t kMaxPoints = 8000;
  std::vector<Eigen::Vector3f> corner;
  for (int i = -30; i <= 30; ++i)
    for (int j = -10; j <= 20; ++j) {
      const float a = 0.1F * static_cast<float>(i);
      const float b = 0.1F * static_cast<float>(j);
      corner.emplace_back(5.0F, a, b);          // a wall ahead
      corner.emplace_back(a + 2.0F, 4.0F, b);   // one to the left
      corner.emplace_back(a + 2.0F, b, -1.0F);  // the floor
    }
  std::atomic<bool> stop{false};
  PipelineStats stats;
  Handoff<MapSlot> scans(4, Overflow::wait, test::map_slot_with_room(kMaxPoints));
  config::Config config;
  config.grid.enabled = false;
  EXPECT_TRUE(config.map.refine);
  MappingStage stage(config, slam::OdometryConfig{}, scans, kMaxPoints, {}, stats, stop);
  stage.start();
  EXPECT_TRUE(stage.refinement().isApprox(Eigen::Isometry3d::Identity()));
  slam::MapRefinerConfig refine;
  refine.max_scan_points = kMaxPoints;
  slam::MapRefiner refiner(refine);
  CornerRun run{Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity()};
  for (int k = 0; k < 10; ++k) {
    if (k >= 3) run.odometry.translation() += Eigen::Vector3d(0.02, 0.0, 0.01);
    run.map_pose = refiner.refine(run.odometry, corner);
    MapSlot* slot = scans.acquire_or_wait([] { return true; });
    if (slot == nullptr) break;
    slot->stamp_ns = 1'000'000'000 + 100'000'000LL * k;
    slot->valid = true;
    slot->anchored = k >= anchored_from;
    slot->pose = run.odometry;
    slot->points.assign(corner.begin(), corner.end());
    slot->times_s.assign(corner.size(), 0.0F);
    slot->intensities.assign(corner.size(), 1.0F);
    scans.publish(slot);
  }
  scans.close();
  stage.join();
  run.refinement = stage.refinement();
  return run;
}

// The refinement holds the scans nearer the map of the first, and
// MappingStage::refinement takes the crept odometry pose to the map's pose,
// as a MapRefiner given the same scans gives it.
TEST(MappingLevel, TheRefinementTakesTheOdometrysPoseToTheMapsPose) {
  const CornerRun run = map_a_creeping_corner(100);
  EXPECT_GT((run.map_pose.translation() - run.odometry.translation()).norm(), 0.05) << "the refinement held nothing back";
  const Eigen::Isometry3d placed = run.refinement * run.odometry;
  EXPECT_LT((placed.translation() - run.map_pose.translation()).norm(), 1e-4)
      << placed.translation().transpose() << " against " << run.map_pose.translation().transpose();
  EXPECT_TRUE(placed.linear().isApprox(run.map_pose.linear(), 1e-6));
}

// Once the odometry is anchored to a prior map, its poses are the map's: the
// map of the scans before the anchor would hold the map to their error.
TEST(MappingLevel, AnAnchoredScanKeepsTheOdometrysPose) {
  const CornerRun run = map_a_creeping_corner(5);
  EXPECT_TRUE(run.refinement.isApprox(Eigen::Isometry3d::Identity(), 1e-12)) << run.refinement.matrix();
}

}  // namespace
}  // namespace adit::daemon
