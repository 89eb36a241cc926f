#pragma once
// A trajectory's pose at any instant between its stamps: slam's
// (slam/trajectory_interpolate.hpp), under the name eval's callers use.

#include "adit/slam/trajectory_interpolate.hpp"

namespace adit::eval {

using slam::interpolate_pose;

}  // namespace adit::eval
