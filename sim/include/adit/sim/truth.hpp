#pragma once
// Ground-truth trajectories in the TUM RGB-D benchmark format (Sturm et al.,
// IROS 2012): one line per pose, "time tx ty tz qx qy qz qw", time in seconds
// on the common clock, the pose of the frame in the world.

#include <cstdint>
#include <filesystem>

#include <Eigen/Geometry>

#include "adit/sim/body_track.hpp"

namespace adit::sim {

// Writes every trajectory sample of body × frame (frame = identity: the body,
// the extrinsics: the sensor). Throws adit::InputError on I/O failure.
void write_tum(const std::filesystem::path& file, const BodyTrack& body, const Eigen::Isometry3d& frame,
               std::int64_t start_time_ns);

}  // namespace adit::sim
