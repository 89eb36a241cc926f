#pragma once
// Reading trajectory files in the formats evaluation tools share (the one
// writer is slam/tum.hpp):
//   TUM RGB-D   "t x y z qx qy qz qw" per line, seconds, '#' comments
//               (https://cvg.cit.tum.de/data/datasets/rgbd-dataset/file_formats)
//   KITTI       12 numbers per line, the row-major 3x4 matrix [R | t]; times,
//               when given, one number per line in a separate file
//   EuRoC CSV   "t_ns,px,py,pz,qw,qx,qy,qz[,...]" with nanosecond stamps
// Malformed lines and times that go backwards throw adit::InputError naming
// "file:line"; readers never skip data silently.

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string_view>

#include "adit/slam/trajectory.hpp"

namespace adit::eval {

enum class TrajectoryFormat { tum, kitti, euroc };

// "tum", "kitti", "euroc"; nullopt for anything else.
std::optional<TrajectoryFormat> parse_trajectory_format(std::string_view name);

// Guesses the format from the file: ".csv" is EuRoC; otherwise the count of
// numbers on the first data line (8: TUM, 12: KITTI). Throws InputError.
TrajectoryFormat detect_trajectory_format(const std::filesystem::path& path);

slam::Trajectory read_tum(const std::filesystem::path& path);
slam::Trajectory read_kitti(const std::filesystem::path& path,
                      const std::optional<std::filesystem::path>& times = std::nullopt);
slam::Trajectory read_euroc_csv(const std::filesystem::path& path);

// The same from a stream; `name` is the file named in errors.
slam::Trajectory read_tum(std::istream& in, const std::filesystem::path& name);
slam::Trajectory read_kitti(std::istream& in, const std::filesystem::path& name);  // untimed
slam::Trajectory read_euroc_csv(std::istream& in, const std::filesystem::path& name);

// Dispatches on `format`; `times` applies to KITTI only.
slam::Trajectory read_trajectory(const std::filesystem::path& path, TrajectoryFormat format,
                           const std::optional<std::filesystem::path>& times = std::nullopt);

}  // namespace adit::eval
