// Scoring moving-object removal against the simulator's people (moving_truth.hpp).

#include <sstream>

#include <gtest/gtest.h>

#include "adit/common/error.hpp"
#include "adit/eval/moving_truth.hpp"

namespace adit::eval {
namespace {

std::vector<PersonSample> read(const std::string& text) {
  std::istringstream in(text);
  return read_people_truth(in, "people.csv");
}

TEST(MovingTruth, ReadsTracksAndNamesBadLines) {
  const auto people = read("# comment\nt,id,x,y,radius_m,height_m\n10.0,0,1.5,-2,0.25,1.75\n10.05,1,3,4,0.25,1.75\n");
  ASSERT_EQ(people.size(), 2u);
  EXPECT_EQ(people[1].id, 1);
  EXPECT_DOUBLE_EQ(people[0].y, -2.0);
  const auto message = [](const std::string& text) {
    try {
      read(text);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("t,id,x,y\n").find("people.csv:1"), std::string::npos);
  EXPECT_NE(message("t,id,x,y,radius_m,height_m\n1,0,x,0,0.25,1.75\n").find("people.csv:2"), std::string::npos);
  EXPECT_NE(message("t,id,x,y,radius_m,height_m\n1,0,0,0,0.25\n").find("6 fields"), std::string::npos);
  EXPECT_NE(message("t,id,x,y,radius_m,height_m\n1,0.5,0,0,0.25,1.75\n").find("id"), std::string::npos);
  EXPECT_NE(message("t,id,x,y,radius_m,height_m\n1,0,0,0,-1,1.75\n").find("radius"), std::string::npos);
  EXPECT_NE(message("").find("header"), std::string::npos);
}

TEST(MovingTruth, LabelsPointsInsideAWalkersSweptCylinder) {
  // One walker going from (0, 0) to (2, 0).
  std::vector<PersonSample> people;
  for (int k = 0; k <= 20; ++k) people.push_back({0.1 * k, 0, 0.1 * k, 0.0, 0.25, 1.75});
  const std::vector<Eigen::Vector3d> points = {
      {1.0, 0.3, 1.0},   // on the way, within radius + margin
      {1.0, 0.5, 1.0},   // beside it
      {1.0, 0.0, 0.05},  // the floor under it
      {1.0, 0.0, 2.0},   // above the head
      {2.2, 0.0, 1.0},   // just past the end, within the margin
      {3.0, 0.0, 1.0}};
  const std::vector<std::uint8_t> l = label_people_points(points, people, MovingLabels{});
  EXPECT_EQ(l, (std::vector<std::uint8_t>{1, 0, 0, 0, 1, 0}));
  const MovingScore s = score_moving(std::span(points).subspan(1), std::span(points).first(1), people, MovingLabels{});
  EXPECT_EQ(s.people_points, 2u);
  EXPECT_EQ(s.people_removed, 1u);
  EXPECT_EQ(s.static_points, 4u);
  EXPECT_EQ(s.static_removed, 0u);
  EXPECT_DOUBLE_EQ(s.people_removed_fraction(), 0.5);
}

}  // namespace
}  // namespace adit::eval
