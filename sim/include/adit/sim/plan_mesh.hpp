#pragma once
// Turns a Plan into a closed triangle mesh: the boundary of the open space is
// traced by marching squares (Lorensen & Cline 1987, in 2-D) on a grid of the
// signed distance, extruded into walls from below the floor to above the roof;
// floor and roof cover the open cells. Every vertex is then displaced by the
// plan's rock roughness (walls along their normal, floor and roof vertically),
// a pure function of position so shared vertices stay shared.

#include "adit/sim/mesh.hpp"
#include "adit/sim/plan.hpp"

namespace adit::sim {

TriangleMesh plan_mesh(const Plan& plan);

}  // namespace adit::sim
