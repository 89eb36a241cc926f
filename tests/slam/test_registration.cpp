#include <cstdio>
#include <limits>

#include <gtest/gtest.h>

#include "adit/slam/lie.hpp"
#include "adit/slam/registration.hpp"
#include "synthetic_scenes.hpp"

namespace adit::slam {
namespace {

Eigen::Isometry3d pose(double x, double y, double z, double yaw_deg, double pitch_deg = 0.0, double roll_deg = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(pitch_deg * M_PI / 180, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll_deg * M_PI / 180, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

double rotation_error_deg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180.0 / M_PI;
}

TEST(Lie, ExpAndLogAreInverse) {
  Vector6d xi;
  xi << 0.3, -1.2, 0.5, 0.2, -0.4, 1.1;
  const Vector6d back = log_se3(exp_se3(xi));
  EXPECT_TRUE(back.isApprox(xi, 1e-9)) << back.transpose();
  EXPECT_TRUE(log_se3(exp_se3(Vector6d::Zero())).isZero(1e-12));
}

TEST(Registration, RecoversAKnownMotionInARoom) {
  VoxelHashMap map(0.5F, 1 << 14);
  map.add(test::room(60000, 1));
  const Eigen::Isometry3d truth = pose(0.25, -0.15, 0.05, 4.0, 1.0, -1.0);
  // The sensor at `truth` sees the room; its points are in its own frame.
  const auto scan = test::transformed(test::room(8000, 2), truth.inverse());
  const RegistrationResult r = register_scan(scan, map, PosePrior{}, 1.0, 0.2);
  EXPECT_LT((r.pose.translation() - truth.translation()).norm(), 0.005);
  EXPECT_LT(rotation_error_deg(r.pose, truth), 0.05);
  EXPECT_FALSE(r.degenerate) << "weakest " << r.weakest_direction.transpose() << " λ " << r.weakest_eigenvalue;
  // Points whose 10 nearest map points straddle an edge of the room have no
  // plane, by design (about 6% of a 12 × 8 × 4 m room at 0.5 m voxels).
  EXPECT_GT(r.inlier_ratio, 0.9);
  EXPECT_LT(r.rmse_m, 0.01);
}

// The prior under the constant-velocity prediction's weight (σ 0.2 rad,
// 0.5 m), 8° off in yaw: narrowed every iteration, the robust kernel weighs
// the residuals that would pull the pose in to nothing within a few
// iterations and the prior keeps it; narrowed only once the update is small,
// it pulls in (decision 042).
TEST(Registration, TheKernelNarrowsOnlyOnceThePoseHasComeIn) {
  VoxelHashMap map(0.5F, 1 << 16);
  map.add(test::room(200000, 5, 25.0F, 12.0F, 4.0F));
  const Eigen::Isometry3d truth = pose(1.0, 0.5, 0.0, 8.0);
  const auto scan = test::transformed(test::room(8000, 6, 25.0F, 12.0F, 4.0F), truth.inverse());
  PosePrior prior;
  Vector6d information;
  information << 4.0, 4.0, 4.0, 25.0, 25.0, 25.0;
  prior.information = information.asDiagonal();
  RegistrationConfig graduated;
  RegistrationConfig every_iteration;
  every_iteration.narrow_below_step = std::numeric_limits<double>::infinity();
  const RegistrationResult pulled_in = register_scan(scan, map, prior, 2.0, 0.67, graduated);
  const RegistrationResult held = register_scan(scan, map, prior, 2.0, 0.67, every_iteration);
  std::printf("8 degrees off: %.3f deg left with the graduated kernel, %.3f narrowed every iteration\n",
              rotation_error_deg(pulled_in.pose, truth), rotation_error_deg(held.pose, truth));
  EXPECT_LT(rotation_error_deg(pulled_in.pose, truth), 0.1);
  EXPECT_LT((pulled_in.pose.translation() - truth.translation()).norm(), 0.02);
  EXPECT_GT(rotation_error_deg(held.pose, truth), 1.0);  // the test bites
}

TEST(Registration, FlagsTheTunnelAxisAndKeepsThePriorThere) {
  VoxelHashMap map(0.5F, 1 << 16);
  map.add(test::tunnel(200000, 3));
  const Eigen::Isometry3d truth = pose(0.0, 0.2, -0.1, 2.0);
  const auto scan = test::transformed(test::tunnel(8000, 4, 60.0F), truth.inverse());
  // The prior (initial guess) is 0.4 m ahead of the truth along the axis.
  PosePrior prior;
  prior.mean = pose(0.4, 0.0, 0.0, 0.0);
  const RegistrationResult r = register_scan(scan, map, prior, 1.0, 0.2);
  ASSERT_TRUE(r.degenerate);
  EXPECT_GT(std::abs(r.weakest_direction(0)), 0.99) << r.weakest_direction.transpose();
  // Along the axis the prior's value stays (the truth is 0.4 m away); the few
  // mm left come from the rotation updates, which act about the world origin.
  EXPECT_NEAR(r.pose.translation().x(), 0.4, 0.01);
  EXPECT_NEAR(r.pose.translation().y(), truth.translation().y(), 0.005);
  EXPECT_NEAR(r.pose.translation().z(), truth.translation().z(), 0.005);
  EXPECT_LT(rotation_error_deg(r.pose, truth), 0.1);
  EXPECT_GT(r.covariance(0, 0), 100.0 * r.covariance(1, 1));  // and it says so in the covariance
}

TEST(Registration, AnInformativePriorDecidesTheDegenerateDirection) {
  VoxelHashMap map(0.5F, 1 << 16);
  map.add(test::tunnel(200000, 5));
  const auto scan = test::transformed(test::tunnel(8000, 6, 60.0F), pose(1.0, 0.0, 0.0, 0.0).inverse());
  PosePrior prior;
  prior.mean = pose(1.3, 0.1, 0.0, 0.0);
  prior.information.diagonal() << 100.0, 100.0, 100.0, 1000.0, 1000.0, 1000.0;  // σ 10 cm, 1.8°
  const RegistrationResult r = register_scan(scan, map, prior, 1.0, 0.2);
  EXPECT_NEAR(r.pose.translation().x(), 1.3, 1e-3);
  EXPECT_NEAR(r.pose.translation().y(), 0.0, 0.005);  // the walls win across the tunnel
}

// Far from the odometry origin a world-frame perturbation mixes rotation into
// translation (a rotation about the origin 200 m away moves the sensor 3.5 m
// per degree): the prior and the degeneracy test must be judged at the sensor.
TEST(Registration, FarFromTheOriginTheRotationIsNotHeldBackByThePrior) {
  const Eigen::Isometry3d far = pose(200.0, -150.0, 10.0, 30.0);
  VoxelHashMap map(0.5F, 1 << 16);
  map.add(test::transformed(test::room(60000, 11), far));
  const Eigen::Isometry3d truth = far * pose(0.2, -0.1, 0.0, 3.0);
  const auto scan = test::transformed(test::room(8000, 12), truth.inverse() * far);
  PosePrior prior;  // constant velocity: the previous pose, loose
  prior.mean = far;
  prior.information.diagonal() << 4.0, 4.0, 4.0, 25.0, 25.0, 25.0;
  const RegistrationResult r = register_scan(scan, map, prior, 1.0, 0.2);
  EXPECT_LT((r.pose.translation() - truth.translation()).norm(), 0.01);
  EXPECT_LT(rotation_error_deg(r.pose, truth), 0.05);
  EXPECT_FALSE(r.degenerate) << "weakest " << r.weakest_direction.transpose() << " λ " << r.weakest_eigenvalue;
}

// A scan measured while the body turns at 20–30°/s (a bump) holds the sweep's
// motion: deskewed with no velocity it registers off; with the velocity
// estimated (continuous time) both the start pose and the motion come back.
TEST(Registration, EstimatesTheSweepVelocityOfAScanMeasuredWhileTurning) {
  VoxelHashMap map(0.5F, 1 << 16);
  map.add(test::room(60000, 21));
  const Eigen::Isometry3d truth = pose(0.2, -0.1, 0.0, 3.0);
  Vector6d velocity;  // body twist per second over the sweep
  velocity << 0.8, 0.1, 0.0, 0.35, -0.45, 0.5;
  const auto world = test::room(8000, 22);
  std::vector<Eigen::Vector3f> measured;
  std::vector<float> times;
  for (std::size_t i = 0; i < world.size(); ++i) {
    const float t = 0.1F * static_cast<float>(i) / static_cast<float>(world.size());
    const Eigen::Isometry3d at_t = truth * exp_se3(velocity * static_cast<double>(t));
    measured.push_back((at_t.inverse() * world[i].cast<double>()).cast<float>());
    times.push_back(t);
  }
  PosePrior prior;
  prior.mean = Eigen::Isometry3d::Identity();
  prior.information.diagonal() << 4.0, 4.0, 4.0, 25.0, 25.0, 25.0;
  std::vector<Eigen::Vector3f> deskewed(measured.size());
  SweepMotion sweep;
  sweep.times_s = times;
  sweep.information.diagonal() << 0.01, 0.01, 0.01, 0.01, 0.01, 0.01;  // σ 10 m/s, 10 rad/s: the data decide
  sweep.deskewed = deskewed;

  sweep.estimate = false;
  const RegistrationResult fixed = register_scan(measured, map, prior, 1.0, 0.2, {}, {}, sweep);
  sweep.estimate = true;
  const RegistrationResult estimated = register_scan(measured, map, prior, 1.0, 0.2, {}, {}, sweep);

  EXPECT_GT(rotation_error_deg(fixed.pose, truth), 0.5) << "the test must hold a motion worth estimating";
  EXPECT_LT((estimated.pose.translation() - truth.translation()).norm(), 0.01);
  EXPECT_LT(rotation_error_deg(estimated.pose, truth), 0.05);
  EXPECT_LT((estimated.sweep_velocity - velocity).norm(), 0.05) << estimated.sweep_velocity.transpose();
  // The scratch holds the scan deskewed with the estimate: at the start pose it lies on the room.
  double worst = 0.0;
  const Eigen::Isometry3f T = truth.cast<float>();
  for (std::size_t i = 0; i < world.size(); ++i) worst = std::max(worst, static_cast<double>((T * deskewed[i] - world[i]).norm()));
  EXPECT_LT(worst, 0.02);
}

// A map tilted by 1° (as one whose early scans went astray) pulls the scan's
// roll and pitch with it; gravity, measured in the body and known in the
// frame, holds them, and leaves yaw and position to the scan.
TEST(Registration, GravityHoldsRollAndPitchAgainstATiltedMap) {
  const Eigen::Isometry3d tilt = pose(0.0, 0.0, 0.0, 0.0, 1.0, -0.5);
  VoxelHashMap map(0.5F, 1 << 14);
  map.add(test::transformed(test::room(60000, 1), tilt));
  const Eigen::Isometry3d truth = pose(0.25, -0.15, 0.05, 4.0, 0.6, -0.4);
  const auto scan = test::transformed(test::room(8000, 2), truth.inverse());
  const RegistrationResult free = register_scan(scan, map, PosePrior{}, 1.0, 0.2);
  EXPECT_LT(rotation_error_deg(free.pose, tilt * truth), 0.05) << "without gravity the scan follows the map";

  PosePrior prior;
  prior.gravity.up_body = truth.linear().transpose() * Eigen::Vector3d::UnitZ();
  prior.gravity.up_frame = Eigen::Vector3d::UnitZ();
  prior.gravity.information = 1.0 / (1e-4 * 1e-4);  // σ 0.006°: gravity decides
  const RegistrationResult held = register_scan(scan, map, prior, 1.0, 0.2);
  const Eigen::Vector3d up = held.pose.linear() * prior.gravity.up_body;
  EXPECT_LT(std::acos(std::min(1.0, up.z())) * 180.0 / M_PI, 0.02) << "the body's up stays the frame's";
  // Yaw is the scan's: the tilted map's heading at the truth, to within what the tilt's coupling moves.
  const auto heading = [](const Eigen::Isometry3d& T) {
    const Eigen::Vector3d x = T.linear() * Eigen::Vector3d::UnitX();
    return std::atan2(x.y(), x.x()) * 180.0 / M_PI;
  };
  EXPECT_NEAR(heading(held.pose), heading(tilt * truth), 0.05);
}

// A prior map in its own frame (A places the registration's frame in it) with
// what the local map lacks: the room's end walls. The local map alone leaves
// the room's axis to the initial guess, 0.3 m off; with the prior the scan
// finds the axis in the prior, through A.
std::vector<Eigen::Vector3f> without_end_walls(const std::vector<Eigen::Vector3f>& points, float hx) {
  std::vector<Eigen::Vector3f> kept;
  for (const auto& p : points)
    if (std::abs(std::abs(p.x()) - hx) > 1e-3F && std::abs(p.x() + 3.0F) > 1e-3F) kept.push_back(p);
  return kept;
}

TEST(Registration, APriorMapHoldsTheAxisTheLocalMapCannotSee) {
  const Eigen::Isometry3d truth = pose(0.5, -0.2, 0.1, 3.0);
  const Eigen::Isometry3d prior_from_frame = pose(120.0, -40.0, 3.0, 70.0, 0.5, -0.3);
  VoxelHashMap local(0.5F, 1 << 14);
  local.add(without_end_walls(test::room(80000, 11), 6.0F));
  VoxelHashMap prior_index(0.5F, 1 << 14);
  prior_index.add(test::transformed(test::room(80000, 12), prior_from_frame));
  const auto scan = test::transformed(test::room(8000, 13), truth.inverse());
  PosePrior guess;
  guess.mean = pose(0.8, -0.2, 0.1, 3.0);
  const RegistrationResult alone = register_scan(scan, local, guess, 1.0, 0.2);
  std::vector<MapPlane> planes(scan.size());
  std::vector<MapPlane> prior_planes(scan.size());
  const RegistrationResult anchored = register_scan(scan, local, guess, 1.0, 0.2, RegistrationConfig{}, planes,
                                                    SweepMotion{}, PriorMapTerm{&prior_index, prior_from_frame, 1.0, prior_planes});
  std::printf("axis error: %.3f m with the local map alone, %.4f m with the prior\n",
              std::abs(alone.pose.translation().x() - truth.translation().x()),
              std::abs(anchored.pose.translation().x() - truth.translation().x()));
  EXPECT_TRUE(alone.degenerate);
  EXPECT_GT(std::abs(alone.pose.translation().x() - truth.translation().x()), 0.25);  // the test bites
  EXPECT_FALSE(anchored.degenerate);
  EXPECT_LT((anchored.pose.translation() - truth.translation()).norm(), 0.005);
  EXPECT_LT(rotation_error_deg(anchored.pose, truth), 0.05);
  EXPECT_GT(anchored.prior_correspondences, 6000);
  EXPECT_EQ(alone.prior_correspondences, 0);
  // Every other point looking up the prior: half the prior's residuals, the axis still held.
  PriorMapTerm every_other{&prior_index, prior_from_frame, 1.0, prior_planes};
  every_other.stride = 2;
  const RegistrationResult halved =
      register_scan(scan, local, guess, 1.0, 0.2, RegistrationConfig{}, planes, SweepMotion{}, every_other);
  EXPECT_NEAR(halved.prior_correspondences, anchored.prior_correspondences / 2, anchored.prior_correspondences / 20);
  EXPECT_LT((halved.pose.translation() - truth.translation()).norm(), 0.005);
}

// What was changed since the prior (a wall moved 0.4 m) does not pull: its
// points find the moved wall's plane beyond the kernel, and the local map and
// the rest of the prior agree.
TEST(Registration, AWallMovedSinceThePriorDoesNotPull) {
  const Eigen::Isometry3d truth = pose(0.3, 0.4, 0.0, -5.0);
  VoxelHashMap local(0.5F, 1 << 14);
  local.add(test::room(80000, 14));
  auto designed = test::room(80000, 15);
  for (auto& p : designed)
    if (std::abs(p.x() - 6.0F) < 1e-3F) p.x() = 6.4F;
  VoxelHashMap prior_index(0.5F, 1 << 14);
  prior_index.add(designed);
  const auto scan = test::transformed(test::room(8000, 16), truth.inverse());
  PosePrior guess;
  guess.mean = pose(0.4, 0.35, 0.0, -4.0);
  std::vector<MapPlane> planes(scan.size());
  std::vector<MapPlane> prior_planes(scan.size());
  const RegistrationResult r = register_scan(scan, local, guess, 1.0, 0.2, RegistrationConfig{}, planes, SweepMotion{},
                                             PriorMapTerm{&prior_index, Eigen::Isometry3d::Identity(), 1.0, prior_planes});
  EXPECT_LT((r.pose.translation() - truth.translation()).norm(), 0.01);
  EXPECT_LT(rotation_error_deg(r.pose, truth), 0.05);
}

TEST(Registration, AnEmptyMapOrScanLeavesThePriorAndFlagsIt) {
  VoxelHashMap map(0.5F, 1024);
  PosePrior prior;
  prior.mean = pose(1.0, 2.0, 0.0, 10.0);
  const auto scan = test::room(100, 7);
  const RegistrationResult r = register_scan(scan, map, prior, 1.0, 0.2);
  EXPECT_TRUE(r.degenerate);
  EXPECT_EQ(r.correspondences, 0);
  EXPECT_TRUE(r.pose.isApprox(prior.mean));
  EXPECT_TRUE(r.covariance.allFinite());
}

}  // namespace
}  // namespace adit::slam
