#include "adit/sim/plan_mesh.hpp"
#include "adit/sim/scene.hpp"

namespace adit::sim {

Scene make_drift(std::uint64_t seed) {
  Scene scene;
  scene.name = "drift";
  Plan& plan = scene.plan;
  plan.seed = seed;
  plan.roof_m = 4.5;
  plan.roof_variation_m = 0.0;
  plan.roughness_m = 0.005;  // shotcrete-smooth: nothing to register along the axis
  plan.drifts.push_back({Eigen::Vector2d(0, 0), Eigen::Vector2d(200, 0), 4.5});
  scene.mesh = plan_mesh(plan);
  scene.route = smooth_route({Eigen::Vector2d(5, 0), Eigen::Vector2d(195, 0)}, false);
  return scene;
}

}  // namespace adit::sim
