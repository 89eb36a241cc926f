// The frame a session's exports are in (daemon/session_frame.hpp): the anchor
// written and read back, a bad prior_frame.json named, a trajectory file moved
// into the prior's frame once only, a stored session's frame, and the LAS
// corner below a moved map.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/daemon/map_files.hpp"
#include "adit/daemon/session_frame.hpp"
#include "adit/slam/levelling.hpp"
#include "adit/slam/tum.hpp"
#include "temp_file.hpp"

namespace adit::daemon {
namespace {

Eigen::Isometry3d sample_anchor() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = (Eigen::AngleAxisd(2.0, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  t.translation() = Eigen::Vector3d(153.25, -48.5, 3.125);
  return t;
}

TEST(SessionFrame, TheAnchorIsReadBackAsWritten) {
  const test::TempFolder dir;
  EXPECT_FALSE(read_prior_frame(dir.path() / "prior_frame.json").has_value());  // none: the odometry frame
  write_prior_frame(dir.path() / "prior_frame.json", sample_anchor());
  const std::optional<Eigen::Isometry3d> back = read_prior_frame(dir.path() / "prior_frame.json");
  ASSERT_TRUE(back.has_value());
  EXPECT_TRUE(back->isApprox(sample_anchor(), 1e-12));
  EXPECT_EQ(frame_summary(export_frame(back, std::nullopt))["name"], "prior_map");
  EXPECT_EQ(frame_summary(ExportFrame{})["name"], "odometry");
}

// Gravity's level (decision 060): kept beside the anchor, which wins over it.
TEST(SessionFrame, TheLevelIsReadBackAsWrittenAndTheAnchorComesFirst) {
  const test::TempFolder dir;
  EXPECT_FALSE(read_level_frame(dir.path() / "level_frame.json").has_value());
  const Eigen::Vector3d up = Eigen::AngleAxisd(0.5 * M_PI / 180, Eigen::Vector3d(1.0, 1.0, 0.0).normalized())
                                 .toRotationMatrix() * Eigen::Vector3d::UnitZ();
  const Eigen::Isometry3d level = slam::level_from_up(up);
  write_level_frame(dir.path() / "level_frame.json", level);
  const std::optional<Eigen::Isometry3d> back = read_level_frame(dir.path() / "level_frame.json");
  ASSERT_TRUE(back.has_value());
  EXPECT_TRUE(back->isApprox(level, 1e-12));
  const nlohmann::json summary = frame_summary(export_frame(std::nullopt, back));
  EXPECT_EQ(summary["name"], "level");
  EXPECT_NEAR(summary["tilt_deg"].get<double>(), 0.5, 1e-9);
  EXPECT_EQ(export_frame(sample_anchor(), back).source, ExportSource::prior_map);
  EXPECT_TRUE(export_frame(sample_anchor(), back).from_odometry.isApprox(sample_anchor()));
  EXPECT_THROW(read_prior_frame(dir.path() / "level_frame.json"), InputError) << "one file's key is not the other's";
}

TEST(SessionFrame, ABadFileIsNamedWithItsKey) {
  const std::pair<const char*, const char*> cases[] = {
      {"not json", "missing"},
      {R"({"other": 1})", "missing"},
      {R"({"prior_from_odometry": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]})", "4 x 4"},
      {R"({"prior_from_odometry": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, "x"], [0, 0, 0, 1]]})", "finite"},
      {R"({"prior_from_odometry": [[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]})", "rigid"},  // a scale
      {R"({"prior_from_odometry": [[-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]})", "rigid"},  // a mirror
      {R"({"prior_from_odometry": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]})", "rigid"},
  };
  for (const auto& [text, why] : cases) {
    try {
      parse_prior_frame(text, "s/prior_frame.json");
      ADD_FAILURE() << text << " was accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.where(), "s/prior_frame.json") << text;
      EXPECT_EQ(e.key(), "prior_from_odometry") << text;
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  }
}

// A finished session's frame as a download after a restart gets it: the
// anchor and, with tiles_graph/, the graph's last correction, as the live
// frame_t had them (map <- tiles = A, map <- odometry = A·C).
TEST(SessionFrame, AStoredSessionsFrameComesFromItsAnchorAndTheGraphsLastCorrection) {
  const test::TempFolder dir;
  EXPECT_FALSE(stored_session_frame(dir.path()).has_value());  // the odometry's own frame
  Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
  correction.linear() = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  correction.translation() = Eigen::Vector3d(0.4, -0.2, 0.05);
  const auto isometry = [](const std::array<double, 3>& p, const std::array<double, 4>& q) {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();
    t.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
    return t;
  };
  const std::filesystem::path graph = dir.path() / kGraphTilesFolder;
  std::filesystem::create_directories(graph);
  write_graph_correction(graph / kGraphCorrectionFile, correction);
  std::optional<MapFrame> f = stored_session_frame(dir.path());
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->source, kFrameSourceLoops);
  EXPECT_TRUE(isometry(f->tiles_position, f->tiles_orientation).isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  EXPECT_TRUE(isometry(f->position, f->orientation).isApprox(correction, 1e-12));

  write_prior_frame(dir.path() / "prior_frame.json", sample_anchor());
  f = stored_session_frame(dir.path());
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->source, kFrameSourcePriorMap);
  EXPECT_TRUE(isometry(f->tiles_position, f->tiles_orientation).isApprox(sample_anchor(), 1e-12));
  EXPECT_TRUE(isometry(f->position, f->orientation).isApprox(sample_anchor() * correction, 1e-12));

  std::filesystem::remove_all(graph);  // no graph's tiles: its tiles/ are in the odometry frame
  f = stored_session_frame(dir.path());
  ASSERT_TRUE(f.has_value());
  EXPECT_TRUE(isometry(f->position, f->orientation).isApprox(sample_anchor(), 1e-12));

  std::filesystem::create_directories(graph);
  std::ofstream(graph / kGraphCorrectionFile) << R"({"graph_from_odometry": [[1, 0, 0, 0]]})";
  try {
    stored_session_frame(dir.path());
    ADD_FAILURE() << "a malformed correction was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), (graph / kGraphCorrectionFile).string());
    EXPECT_EQ(e.key(), "graph_from_odometry");
  }
}

TEST(SessionFrame, ATrajectoryIsMovedIntoThePriorsFrameOnce) {
  const test::TempFolder dir;
  const std::filesystem::path file = dir.path() / "trajectory.tum";
  slam::Trajectory t;
  for (int i = 0; i < 5; ++i) {
    Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
    p.linear() = Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    p.translation() = Eigen::Vector3d(0.5 * i, 0.1 * i, 0.0);
    t.stamps.push_back(1.7e9 + 0.1 * i);
    t.poses.push_back(p);
  }
  slam::write_tum(file, t);
  const ExportFrame anchored = export_frame(sample_anchor(), std::nullopt);
  EXPECT_FALSE(place_trajectory_file(dir.path() / "none.tum", anchored));
  ASSERT_TRUE(place_trajectory_file(file, anchored));
  ASSERT_TRUE(place_trajectory_file(file, anchored));  // again (a recovery after a crash here): unchanged
  const slam::Trajectory back = slam::read_tum(file);
  ASSERT_EQ(back.size(), t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_NEAR(back.stamps[i], t.stamps[i], 1e-6);
    EXPECT_LT(((sample_anchor() * t.poses[i]).translation() - back.poses[i].translation()).norm(), 2e-6) << i;
    EXPECT_TRUE((sample_anchor() * t.poses[i]).linear().isApprox(back.poses[i].linear(), 1e-6)) << i;
  }
}

// `n` poses 0.1 s apart, turning by `yaw` rad and moving by `step` a pose,
// and their stamps (ns).
slam::Trajectory turning_path(int n, double yaw, const Eigen::Vector3d& step, std::vector<std::int64_t>& stamps_ns) {
  slam::Trajectory t;
  for (int i = 0; i < n; ++i) {
    Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
    p.linear() = Eigen::AngleAxisd(yaw * i, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    p.translation() = step * i;
    stamps_ns.push_back(1'700'000'000'000'000'000 + 100'000'000LL * i);
    t.push_back(1e-9 * static_cast<double>(stamps_ns.back()), p);
  }
  return t;
}

// With loop closure the map files are moved by the graph's correction C(t)
// (slam::CorrectionTrack); the trajectories go with them, then into the
// prior's frame when anchored: anchor·C(t)·T, once.
TEST(SessionFrame, ATrajectoryIsMovedByTheGraphsCorrectionAsTheMapIs) {
  const test::TempFolder dir;
  std::vector<std::int64_t> stamps_ns;
  const slam::Trajectory t = turning_path(5, 0.1, Eigen::Vector3d(0.5, 0.1, 0.0), stamps_ns);
  // Keyframes 0 and 4: the graph levelled the first (pitched 0.3°) and moved the last 0.2 m up.
  Eigen::Isometry3d first = t.poses[0];
  first.linear() = Eigen::AngleAxisd(0.3 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix() * first.linear();
  Eigen::Isometry3d last = t.poses[4];
  last.translation().z() += 0.2;
  const std::vector<std::int64_t> keyframes{stamps_ns[0], stamps_ns[4]};
  const std::vector<Eigen::Isometry3d> graph{first, last};
  const std::vector<Eigen::Isometry3d> odometry{t.poses[0], t.poses[4]};
  const slam::CorrectionTrack track(keyframes, graph, odometry);
  Eigen::Isometry3d level = Eigen::Isometry3d::Identity();
  level.linear() = Eigen::AngleAxisd(0.4 * M_PI / 180, Eigen::Vector3d::UnitX()).toRotationMatrix();
  for (const ExportSource source : {ExportSource::odometry, ExportSource::prior_map, ExportSource::level}) {
    const std::filesystem::path file = dir.path() / fmt::format("trajectory-{}.tum", static_cast<int>(source));
    slam::write_tum(file, t);
    const ExportFrame placed = export_frame(source == ExportSource::prior_map ? std::optional(sample_anchor()) : std::nullopt,
                                            source == ExportSource::level ? std::optional(level) : std::nullopt);
    const Eigen::Isometry3d& frame = placed.from_odometry;
    ASSERT_TRUE(place_trajectory_file(file, placed, &track));
    ASSERT_TRUE(place_trajectory_file(file, placed, &track));  // again: unchanged
    std::ifstream in(file);
    std::string line;
    std::getline(in, line);
    const char* expected = source == ExportSource::prior_map ? "# frame: prior_map (the pose graph's"
                           : source == ExportSource::level   ? "# frame: level (the pose graph's"
                                                             : "# frame: loops";
    EXPECT_EQ(line.rfind(expected, 0), 0U) << line;
    const slam::Trajectory back = slam::read_tum(file);
    ASSERT_EQ(back.size(), t.size());
    for (std::size_t i = 0; i < t.size(); ++i) {
      const Eigen::Isometry3d want = frame * track.at(stamps_ns[i]) * t.poses[i];
      EXPECT_LT((want.translation() - back.poses[i].translation()).norm(), 2e-6) << i;
      EXPECT_TRUE(want.linear().isApprox(back.poses[i].linear(), 1e-6)) << i;
    }
    EXPECT_TRUE((frame * graph[0]).isApprox(back.poses[0], 1e-6));  // where the graph put keyframe 0
    EXPECT_NEAR((frame * graph[1]).translation().z(), back.poses[4].translation().z(), 2e-6);
  }
}

// The odometry's trajectory.tum is not the path the map was built at
// (map_trajectory.tum: the refinement moved it), and the graph's correction
// is against the latter: both files end where the graph put the map's poses.
TEST(SessionFrame, BothTrajectoriesEndWhereTheGraphPutTheMapsPoses) {
  const test::TempFolder dir;
  std::vector<std::int64_t> stamps_ns;
  const slam::Trajectory built_at = turning_path(6, 0.05, Eigen::Vector3d(1.0, 0.2, 0.0), stamps_ns);
  slam::Trajectory odometry = built_at;
  for (std::size_t i = 0; i < odometry.size(); ++i)
    odometry.poses[i].translation().z() += 0.05 * static_cast<double>(i);  // it climbs; the refinement held the map level
  Eigen::Isometry3d last = built_at.poses[5];
  last.translation() += Eigen::Vector3d(0.1, -0.3, 0.02);
  const std::vector<std::int64_t> keyframes{stamps_ns[0], stamps_ns[5]};
  const std::vector<Eigen::Isometry3d> graph{built_at.poses[0], last};
  const std::vector<Eigen::Isometry3d> map_keyframes{built_at.poses[0], built_at.poses[5]};
  const slam::CorrectionTrack track(keyframes, graph, map_keyframes);
  Eigen::Isometry3d level = Eigen::Isometry3d::Identity();
  level.linear() = Eigen::AngleAxisd(0.4 * M_PI / 180, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const ExportFrame frame = export_frame(std::nullopt, level);
  slam::write_tum(dir.path() / "trajectory.tum", odometry);
  slam::write_tum(dir.path() / "map_trajectory.tum", built_at);
  place_session_trajectories(dir.path(), frame, &track);
  place_session_trajectories(dir.path(), frame, &track);  // again (a recovery): unchanged
  for (const char* name : {"trajectory.tum", "map_trajectory.tum"}) {
    const slam::Trajectory back = slam::read_tum(dir.path() / name);
    ASSERT_EQ(back.size(), built_at.size()) << name;
    for (std::size_t i = 0; i < back.size(); ++i) {
      const Eigen::Isometry3d want = level * track.at(stamps_ns[i]) * built_at.poses[i];
      EXPECT_LT((want.translation() - back.poses[i].translation()).norm(), 2e-6) << name << " " << i;
      EXPECT_TRUE(want.linear().isApprox(back.poses[i].linear(), 1e-6)) << name << " " << i;
    }
    EXPECT_LT(((level * last).translation() - back.poses[5].translation()).norm(), 2e-6) << name;
  }
}

// frame_t's map <- odometry is A·C·D: the poses land among the tiles, which
// hold the scans at the refined poses; map <- tiles stays A.
TEST(SessionFrame, ThePosesArePlacedByTheMapsRefinement) {
  Eigen::Isometry3d refinement = Eigen::Isometry3d::Identity();
  refinement.translation() = Eigen::Vector3d(0.02, -0.01, -0.4);
  refinement.linear() = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY()).toRotationMatrix();
  Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
  correction.translation() = Eigen::Vector3d(0.3, 0.0, 0.1);
  const auto odometry_of = [](const MapFrame& f) {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.translation() = Eigen::Vector3d(f.position[0], f.position[1], f.position[2]);
    t.linear() = Eigen::Quaterniond(f.orientation[0], f.orientation[1], f.orientation[2], f.orientation[3]).toRotationMatrix();
    return t;
  };
  EXPECT_FALSE(map_frame_of(ExportFrame{}, std::nullopt).has_value());
  const std::optional<MapFrame> own = map_frame_of(ExportFrame{}, std::nullopt, refinement);
  ASSERT_TRUE(own.has_value()) << "the refinement alone moves the poses";
  EXPECT_EQ(own->source, kFrameSourceOdometry);
  EXPECT_TRUE(odometry_of(*own).isApprox(refinement, 1e-9));
  EXPECT_EQ(own->tiles_position, (std::array<double, 3>{0.0, 0.0, 0.0}));
  const ExportFrame anchored = export_frame(sample_anchor(), std::nullopt);
  const std::optional<MapFrame> all = map_frame_of(anchored, correction, refinement);
  ASSERT_TRUE(all.has_value());
  EXPECT_TRUE(odometry_of(*all).isApprox(sample_anchor() * correction * refinement, 1e-9));
  EXPECT_NEAR(all->tiles_position[2], sample_anchor().translation().z(), 1e-12);
}

TEST(SessionFrame, TheMapCornerStaysBelowAMovedMap) {
  const std::vector<slam::TileCoord> coords{{0, 0, 0}, {1, 2, 0}, {-1, 0, 1}};
  const double tile = 20.0;
  const std::array<double, 3> plain = map_corner(coords, tile, 0.0, Eigen::Isometry3d::Identity());
  EXPECT_EQ(plain, (std::array<double, 3>{-20.0, 0.0, 0.0}));
  const Eigen::Isometry3d anchor = sample_anchor();
  const std::array<double, 3> moved = map_corner(coords, tile, 0.5, anchor);
  for (const slam::TileCoord& c : coords)
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d p = anchor * (Eigen::Vector3d(c.x, c.y, c.z) * tile +
                                          tile * Eigen::Vector3d((k & 1) != 0, (k & 2) != 0, (k & 4) != 0));
      for (int a = 0; a < 3; ++a) EXPECT_LE(moved[static_cast<std::size_t>(a)], p[a] - 0.5);
    }
}

}  // namespace
}  // namespace adit::daemon
