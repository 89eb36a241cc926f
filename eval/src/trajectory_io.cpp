#include "adit/eval/trajectory_io.hpp"

#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/slam/tum.hpp"
#include "text_fields.hpp"

namespace adit::eval {
namespace {

namespace fs = std::filesystem;

std::string at(const fs::path& path, std::size_t line) { return fmt::format("{}:{}", path.string(), line); }

std::ifstream open(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), "", "cannot open for reading");
  return in;
}

// Calls `on_line(fields, line_number)` for every data line, split at `separators`.
template <typename OnLine>
void for_each_data_line(std::istream& in, std::string_view separators, OnLine&& on_line) {
  std::string line;
  std::vector<std::string_view> fields;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    if (detail::is_comment_or_blank(line)) continue;
    detail::split_fields(line, separators, fields);
    on_line(fields, number);
  }
}

// Parses fields[first, first+count) as doubles into `out`, or throws naming the field.
void parse_numbers(const std::vector<std::string_view>& fields, std::size_t first, std::size_t count,
                   const fs::path& path, std::size_t line, double* out) {
  for (std::size_t k = 0; k < count; ++k) {
    const auto value = detail::parse_double(fields[first + k]);
    if (!value)
      throw InputError(at(path, line), fmt::format("field {}", first + k + 1),
                       fmt::format("'{}' is not a finite number", fields[first + k]));
    out[k] = *value;
  }
}

slam::Pose pose_from(const Eigen::Vector3d& t, Eigen::Quaterniond q, const fs::path& path, std::size_t line) {
  const double norm = q.norm();
  if (norm < 1e-6) throw InputError(at(path, line), "quaternion", "has zero length");
  q.coeffs() /= norm;  // files carry rounded quaternions
  slam::Pose pose = slam::Pose::Identity();
  pose.linear() = q.toRotationMatrix();
  pose.translation() = t;
  return pose;
}

void check_forward(const slam::Trajectory& traj, double stamp, const fs::path& path, std::size_t line) {
  if (!traj.stamps.empty() && stamp < traj.stamps.back())
    throw InputError(at(path, line), "timestamp",
                     fmt::format("goes backwards: {:.9f} after {:.9f}", stamp, traj.stamps.back()));
}

void expect_fields(const std::vector<std::string_view>& fields, std::size_t count, bool at_least,
                   std::string_view layout, const fs::path& path, std::size_t line) {
  if (fields.size() == count || (at_least && fields.size() > count)) return;
  throw InputError(
      at(path, line), "",
      fmt::format("expected {}{} fields ({}), found {}", at_least ? "at least " : "", count, layout, fields.size()));
}

void expect_poses(const slam::Trajectory& traj, const fs::path& path) {
  if (traj.empty()) throw InputError(path.string(), "", "contains no poses");
}

}  // namespace

std::optional<TrajectoryFormat> parse_trajectory_format(std::string_view name) {
  if (name == "tum") return TrajectoryFormat::tum;
  if (name == "kitti") return TrajectoryFormat::kitti;
  if (name == "euroc") return TrajectoryFormat::euroc;
  return std::nullopt;
}

TrajectoryFormat detect_trajectory_format(const fs::path& path) {
  if (path.extension() == ".csv") return TrajectoryFormat::euroc;
  std::ifstream in = open(path);
  std::string line;
  std::vector<std::string_view> fields;
  while (std::getline(in, line)) {
    if (detail::is_comment_or_blank(line)) continue;
    detail::split_fields(line, " \t", fields);
    if (fields.size() == 8) return TrajectoryFormat::tum;
    if (fields.size() == 12) return TrajectoryFormat::kitti;
    break;
  }
  throw InputError(path.string(), "format",
                   "cannot tell the format (8 numbers per line: TUM, 12: KITTI, .csv: EuRoC); name it explicitly");
}

// TUM has one reader, beside the one writer (slam/tum.hpp).
slam::Trajectory read_tum(const fs::path& path) { return slam::read_tum(path); }

slam::Trajectory read_tum(std::istream& in, const fs::path& path) { return slam::read_tum(in, path); }

slam::Trajectory read_kitti(std::istream& in, const fs::path& path) {
  slam::Trajectory traj;
  for_each_data_line(in, " \t", [&](const std::vector<std::string_view>& fields, std::size_t line) {
    expect_fields(fields, 12, false, "row-major 3x4 matrix", path, line);
    double v[12];
    parse_numbers(fields, 0, 12, path, line, v);
    slam::Pose pose = slam::Pose::Identity();
    // Kept as written: evaluation tools use the stored matrix, not a re-orthonormalised one.
    pose.matrix().topRows<3>() = Eigen::Map<const Eigen::Matrix<double, 3, 4, Eigen::RowMajor>>(v);
    traj.push_back(static_cast<double>(traj.size()), pose);
  });
  expect_poses(traj, path);
  traj.timed = false;
  return traj;
}

slam::Trajectory read_kitti(const fs::path& path, const std::optional<fs::path>& times) {
  std::ifstream in = open(path);
  slam::Trajectory traj = read_kitti(in, path);
  if (!times) return traj;
  traj.timed = true;

  std::size_t count = 0;
  std::ifstream times_in = open(*times);
  for_each_data_line(times_in, " \t,", [&](const std::vector<std::string_view>& fields, std::size_t line) {
    expect_fields(fields, 1, false, "one time in seconds", *times, line);
    double t = 0.0;
    parse_numbers(fields, 0, 1, *times, line, &t);
    if (count < traj.size()) {
      if (count > 0 && t < traj.stamps[count - 1])
        throw InputError(at(*times, line), "timestamp",
                         fmt::format("goes backwards: {:.9f} after {:.9f}", t, traj.stamps[count - 1]));
      traj.stamps[count] = t;
    }
    ++count;
  });
  if (count != traj.size())
    throw InputError(times->string(), "",
                     fmt::format("has {} times for {} poses in {}", count, traj.size(), path.string()));
  return traj;
}

slam::Trajectory read_euroc_csv(const fs::path& path) {
  std::ifstream in = open(path);
  return read_euroc_csv(in, path);
}

slam::Trajectory read_euroc_csv(std::istream& in, const fs::path& path) {
  slam::Trajectory traj;
  for_each_data_line(in, ",", [&](const std::vector<std::string_view>& fields, std::size_t line) {
    expect_fields(fields, 8, true, "t_ns,px,py,pz,qw,qx,qy,qz", path, line);
    const auto ns = detail::parse_int64(fields[0]);
    if (!ns) throw InputError(at(path, line), "field 1", fmt::format("'{}' is not an integer of ns", fields[0]));
    double v[7];
    parse_numbers(fields, 1, 7, path, line, v);
    const double stamp = static_cast<double>(*ns) * 1e-9;
    check_forward(traj, stamp, path, line);
    traj.push_back(stamp, pose_from({v[0], v[1], v[2]}, Eigen::Quaterniond(v[3], v[4], v[5], v[6]), path, line));
  });
  expect_poses(traj, path);
  return traj;
}

slam::Trajectory read_trajectory(const fs::path& path, TrajectoryFormat format, const std::optional<fs::path>& times) {
  switch (format) {
    case TrajectoryFormat::tum: return read_tum(path);
    case TrajectoryFormat::kitti: return read_kitti(path, times);
    case TrajectoryFormat::euroc: return read_euroc_csv(path);
  }
  throw InputError(path.string(), "format", "unknown trajectory format");
}

}  // namespace adit::eval
