#pragma once
// Scoring the removal of moving objects (adit products' moving_points.ply and
// map_static) against the simulator's people (truth_people.csv, written by
// `adit sim --people N`): a map point, placed in the world, is a person's
// when it lies inside a walker's cylinder (radius and height from the file,
// widened by `margin_m`) at some instant of its track and above the floor by
// `floor_margin_m` (lower, a point of a foot and of the floor cannot be told
// apart); every other point is static.

#include <cstddef>
#include <filesystem>
#include <istream>
#include <string>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace adit::eval {

struct PersonSample {
  double t = 0.0;
  int id = 0;
  double x = 0.0, y = 0.0;  // the cylinder's axis, world frame
  double radius_m = 0.25, height_m = 1.75;
};

// truth_people.csv (comment lines, then `t,id,x,y,radius_m,height_m`). Throws
// adit::InputError naming the file and line.
std::vector<PersonSample> read_people_truth(const std::filesystem::path& file);
std::vector<PersonSample> read_people_truth(std::istream& in, const std::string& name);

struct MovingLabels {
  double margin_m = 0.10;       // cylinder widened by this (the map's own error against the truth)
  double floor_margin_m = 0.10;
  double floor_z = 0.0;
};

// 1 where a world point is a person's.
std::vector<std::uint8_t> label_people_points(std::span<const Eigen::Vector3d> world_points,
                                              std::span<const PersonSample> people, const MovingLabels& options);

struct MovingScore {
  std::size_t people_points = 0, people_removed = 0;
  std::size_t static_points = 0, static_removed = 0;
  double people_removed_fraction() const { return people_points ? double(people_removed) / double(people_points) : 0.0; }
  double static_removed_fraction() const { return static_points ? double(static_removed) / double(static_points) : 0.0; }
};

// Both sets of the map's points in the world (kept: map_static, removed: moving_points).
MovingScore score_moving(std::span<const Eigen::Vector3d> kept, std::span<const Eigen::Vector3d> removed,
                         std::span<const PersonSample> people, const MovingLabels& options);

}  // namespace adit::eval
