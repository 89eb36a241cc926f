#include "adit/sim/hash_noise.hpp"
#include "adit/sim/plan_mesh.hpp"
#include "adit/sim/scene.hpp"

namespace adit::sim {

Scene make_mine(std::uint64_t seed) {
  std::uint64_t draw = 0;
  const auto u = [&](double lo, double hi) { return lo + (hi - lo) * uniform(seed, 0x4D696E65ULL, draw++); };
  // The main loop: a jittered rectangle whose edges bend at jittered midpoints.
  const double lx = u(70, 95), ly = u(40, 55);
  const auto corner = [&](double x, double y) { return Eigen::Vector2d(x + u(-4, 4), y + u(-4, 4)); };
  const Eigen::Vector2d c0 = corner(0, 0), c1 = corner(lx, 0), c2 = corner(lx, ly), c3 = corner(0, ly);
  const auto bend = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const Eigen::Vector2d d = (b - a).normalized();
    return Eigen::Vector2d(0.5 * (a + b) + Eigen::Vector2d(-d.y(), d.x()) * u(-5, 5));
  };
  const Eigen::Vector2d m0 = bend(c0, c1), m1 = bend(c1, c2), m2 = bend(c2, c3), m3 = bend(c3, c0);
  const std::vector<Eigen::Vector2d> loop{m3, c0, m0, c1, m1, c2, m2, c3};

  Scene scene;
  scene.name = "mine";
  Plan& plan = scene.plan;
  plan.seed = seed;
  plan.roof_m = u(4.3, 4.7);
  plan.roof_variation_m = 0.3;  // roofs 4-5 m
  plan.roughness_m = 0.1;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    plan.drifts.push_back({loop[i], loop[(i + 1) % loop.size()], u(3.5, 5.0)});
  }
  // A cross-cut between the long edges' bends: two T-junctions and a second loop.
  plan.drifts.push_back({m0, m2, u(3.5, 4.5)});
  // A dead-end branch off the bottom edge, and a branch to a stope off the right edge.
  plan.drifts.push_back({c0 + (m0 - c0) * 0.4, c0 + (m0 - c0) * 0.4 + Eigen::Vector2d(u(-5, 5), -u(18, 28)), 4.0});
  const Eigen::Vector2d stope = m1 + Eigen::Vector2d(u(22, 30), u(-5, 5));
  plan.drifts.push_back({m1, stope, 4.5});
  plan.chambers.push_back({stope, u(7, 10), u(7, 9)});

  scene.mesh = plan_mesh(plan);
  scene.route = smooth_route(loop, true);
  return scene;
}

}  // namespace adit::sim
