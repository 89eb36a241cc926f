#include "adit/sim/hash_noise.hpp"
#include "adit/sim/plan_mesh.hpp"
#include "adit/sim/scene.hpp"

namespace adit::sim {
namespace {

constexpr double kWall = 0.2;       // partition thickness
constexpr double kDoor = 0.9;       // door width
constexpr double kLength = 40.0;    // floor length (x)
constexpr double kCorridorA = 7.0;  // corridor centre lines (y)
constexpr double kCorridorB = 19.0;
constexpr double kCorridorWidth = 2.0;

// A row of rooms between y0 and y1, each with a door to the corridor at door_y.
void add_room_row(Plan& plan, double y0, double y1, double door_y, std::uint64_t seed, std::uint64_t row,
                  double moved_partition, int moved_index, std::vector<Box2>& out_rooms) {
  double x = 1.0;
  int index = 0;
  while (x < kLength - 4.0) {
    double width = 4.0 + 3.0 * uniform(seed, 0x526F6F6DULL + row, static_cast<std::uint64_t>(index));
    if (x + width > kLength - 1.0) width = kLength - 1.0 - x;
    double right = x + width;
    if (index == moved_index) right += moved_partition;  // the built wall is not where it was drawn
    Box2 room{{x, y0}, {right, y1}};
    plan.rooms.push_back(room);
    out_rooms.push_back(room);
    const double door_x = x + 0.5 * (right - x);
    const double inside_y = 0.5 * (y0 + y1);
    plan.drifts.push_back({Eigen::Vector2d(door_x, door_y), Eigen::Vector2d(door_x, inside_y), kDoor});
    x = right + kWall;
    ++index;
  }
}

Plan building_plan(std::uint64_t seed, bool as_built, std::vector<Box2>& rooms) {
  Plan plan;
  plan.seed = seed;
  plan.roof_m = 3.0;
  plan.roof_variation_m = 0.0;
  plan.roughness_m = 0.0;  // plaster: flat
  plan.wall_reflectivity = 70;
  plan.cell_m = 0.1;
  // The corridor loop.
  const Eigen::Vector2d a0(1.5, kCorridorA), a1(kLength - 1.5, kCorridorA);
  const Eigen::Vector2d b0(1.5, kCorridorB), b1(kLength - 1.5, kCorridorB);
  plan.drifts.push_back({a0, a1, kCorridorWidth});
  plan.drifts.push_back({a1, b1, kCorridorWidth});
  plan.drifts.push_back({b1, b0, kCorridorWidth});
  plan.drifts.push_back({b0, a0, kCorridorWidth});
  const double half = 0.5 * kCorridorWidth + kWall;
  const int moved = static_cast<int>(3.0 * uniform(seed, 0x4D6F7665ULL, 0));
  add_room_row(plan, 0.0, kCorridorA - half, kCorridorA, seed, 0, as_built ? 0.3 : 0.0, moved, rooms);
  add_room_row(plan, kCorridorB + half, kCorridorB + half + 5.0, kCorridorB, seed, 1, 0.0, -1, rooms);
  // Between the corridors: an open hall with two rows of pillars, reached from both corridors.
  const Box2 hall{{3.0, kCorridorA + half}, {kLength - 3.0, kCorridorB - half}};
  plan.rooms.push_back(hall);
  for (double x = 8.0; x < kLength - 6.0; x += 6.0) {
    for (const double y : {kCorridorA + 4.0, kCorridorB - 4.0}) {
      plan.pillars.push_back({{x - 0.2, y - 0.2}, {x + 0.2, y + 0.2}});
    }
  }
  for (const double x : {10.0, 30.0}) {
    plan.drifts.push_back({Eigen::Vector2d(x, kCorridorA), Eigen::Vector2d(x, kCorridorA + 2.0), 1.8});
    plan.drifts.push_back({Eigen::Vector2d(x, kCorridorB), Eigen::Vector2d(x, kCorridorB - 2.0), 1.8});
  }
  return plan;
}

}  // namespace

Scene make_building(std::uint64_t seed) {
  Scene scene;
  scene.name = "building";
  std::vector<Box2> rooms;
  scene.plan = building_plan(seed, true, rooms);
  scene.mesh = plan_mesh(scene.plan);
  // Furniture in the rooms (desks and cabinets), not in the design model.
  std::uint64_t draw = 0;
  const auto u = [&](double lo, double hi) { return lo + (hi - lo) * uniform(seed, 0x46757272ULL, draw++); };
  for (const Box2& room : rooms) {
    const int items = 1 + static_cast<int>(u(0, 2.99));
    for (int k = 0; k < items; ++k) {
      const bool desk = u(0, 1) < 0.6;
      const double w = desk ? 1.6 : 0.5, d = desk ? 0.8 : 1.0, h = desk ? 0.75 : 2.0;
      // Against the back wall, away from the door in the middle of the front.
      const double x = u(room.lo.x() + 0.3, std::max(room.lo.x() + 0.3, room.hi.x() - 0.3 - w));
      const bool low_side = room.hi.y() < kCorridorA;  // rooms below corridor A face +y
      const double y = low_side ? room.lo.y() + 0.05 : room.hi.y() - 0.05 - d;
      scene.mesh.add_box(Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y), 0.0F),
                         Eigen::Vector3f(static_cast<float>(x + w), static_cast<float>(y + d), static_cast<float>(h)),
                         desk ? 40 : 60);
    }
  }
  std::vector<Box2> designed_rooms;
  scene.design = plan_mesh(building_plan(seed, false, designed_rooms));
  scene.route = smooth_route({Eigen::Vector2d(1.5, kCorridorA), Eigen::Vector2d(kLength - 1.5, kCorridorA),
                              Eigen::Vector2d(kLength - 1.5, kCorridorB), Eigen::Vector2d(1.5, kCorridorB)},
                             true, 1.0);
  return scene;
}

}  // namespace adit::sim
