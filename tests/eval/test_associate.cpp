#include <cmath>

#include <gtest/gtest.h>

#include "adit/eval/associate.hpp"
#include "brute_nearest.hpp"

namespace adit::eval {
namespace {
using slam::Pose;
using slam::Trajectory;

TEST(Associate, HundredHertzAgainstThirtyHertz) {
  std::vector<double> ref, est;
  for (int i = 0; i < 300; ++i) ref.push_back(0.01 * i);
  for (int i = 0; i < 100; ++i) est.push_back(0.0005 + i / 30.0);  // runs 0.3 s past the reference
  const auto pairs = associate(ref, est, 0.005);
  // Est stamps up to 2.99 + 0.005 match: i / 30 <= 2.9945, i.e. i <= 89.
  ASSERT_EQ(pairs.size(), 90u);
  for (const auto& [i, j] : pairs) {
    EXPECT_EQ(i, brute_nearest(ref, est[j]));
    EXPECT_LE(std::abs(ref[i] - est[j]), 0.005);
  }
}

TEST(Associate, MaxDifferenceAndOffsetApply) {
  const std::vector<double> ref{0.0, 1.0, 2.0}, est{0.2, 1.05, 2.3};
  EXPECT_EQ(associate(ref, est, 0.1), (std::vector<IndexPair>{{1, 1}}));
  // With the offset added to the estimate stamps: 0.0, 0.85, 2.1.
  EXPECT_EQ(associate(ref, est, 0.1, -0.2), (std::vector<IndexPair>{{0, 0}, {2, 2}}));
  EXPECT_TRUE(associate(ref, std::vector<double>{5.0, 6.0}, 0.1).empty());
}

TEST(Associate, EachPoseUsedOnceClosestWins) {
  const std::vector<double> ref{1.0, 5.0, 9.0}, est{0.98, 1.01, 5.0, 9.0};
  EXPECT_EQ(associate(ref, est, 0.05), (std::vector<IndexPair>{{0, 1}, {1, 2}, {2, 3}}));
}

}  // namespace
}  // namespace adit::eval
