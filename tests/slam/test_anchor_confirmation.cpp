// Two tries' anchors agreeing make one taken (slam/anchor_confirmation.hpp):
// the first found waits; one that places the next cloud's frame within 0.3 m
// and 2° of where the one before places it is taken; one further off, or
// turned further, takes the earlier one's place and waits in its turn.
#include <gtest/gtest.h>

#include <cmath>

#include "adit/slam/anchor_confirmation.hpp"

namespace adit::slam {
namespace {

Eigen::Isometry3d pose(double x, double y, double yaw_deg) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.translation() << x, y, 0.0;
  return t;
}

TEST(AnchorConfirmation, TheFirstFoundWaitsAndAnAgreeingOneIsTaken) {
  AnchorConfirmation c;
  const Eigen::Isometry3d anchor = pose(20.0, -7.0, 135.0);
  EXPECT_FALSE(c.waiting());
  EXPECT_FALSE(c.agrees(anchor, pose(1.0, 2.0, 10.0)));
  EXPECT_TRUE(c.waiting());
  // The next cloud, 3 m on and turned 40°: the same anchor, found 5 cm and 0.3° off.
  EXPECT_TRUE(c.agrees(pose(0.05, 0.0, 0.3) * anchor, pose(4.0, 2.0, 50.0)));
}

TEST(AnchorConfirmation, ARivalReplacesTheOneBeforeAndWaits) {
  AnchorConfirmation c;
  const Eigen::Isometry3d right = pose(20.0, -7.0, 135.0);
  // The floor's half-turn twin, then the right one: neither is taken yet.
  const Eigen::Isometry3d twin = pose(17.4, 0.0, 0.0) * right * pose(0.0, 0.0, 180.0);
  EXPECT_FALSE(c.agrees(twin, pose(1.0, 2.0, 10.0)));
  EXPECT_FALSE(c.agrees(right, pose(2.0, 2.0, 10.0)));
  // The right one again: taken, not the twin.
  EXPECT_TRUE(c.agrees(right, pose(3.0, 2.0, 10.0)));
}

TEST(AnchorConfirmation, OneAnswerIsWithinTheRivalDistances) {
  const Eigen::Isometry3d anchor = pose(5.0, 5.0, 30.0);
  const Eigen::Isometry3d cloud = pose(10.0, 0.0, 0.0);
  const auto second_agrees = [&](const Eigen::Isometry3d& offset) {
    AnchorConfirmation c;
    c.agrees(anchor, cloud);
    // The offset applies at the cloud's frame, where the two are compared.
    return c.agrees(anchor * cloud * offset * cloud.inverse(), cloud);
  };
  EXPECT_TRUE(second_agrees(pose(0.25, 0.0, 0.0)));
  EXPECT_FALSE(second_agrees(pose(0.35, 0.0, 0.0)));
  EXPECT_TRUE(second_agrees(pose(0.0, 0.0, 1.8)));
  EXPECT_FALSE(second_agrees(pose(0.0, 0.0, 2.2)));
}

// Each try of a confirmed pair accepts a lower overlap than a lone try; the
// other checks stay as given.
TEST(AnchorConfirmation, AConfirmedPairsTriesAcceptALowerOverlap) {
  LocalisationConfig base;
  base.min_rival_miss_ratio = 1.7;
  const LocalisationConfig c = confirmed_localisation(base);
  EXPECT_DOUBLE_EQ(c.min_overlap, 0.85);
  EXPECT_LT(c.min_overlap, LocalisationConfig{}.min_overlap);
  EXPECT_DOUBLE_EQ(c.min_rival_miss_ratio, 1.7);
  EXPECT_DOUBLE_EQ(c.rival_m, base.rival_m);
}

}  // namespace
}  // namespace adit::slam
