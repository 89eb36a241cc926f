#include "adit/slam/tum.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::slam {
namespace {

// One line into a stack buffer: no allocation.
fmt::format_to_n_result<char*> format_line(char* out, std::size_t size, std::int64_t stamp_ns, const Pose& pose) {
  const Eigen::Quaterniond q(pose.linear());
  const Eigen::Vector3d& t = pose.translation();
  const std::uint64_t magnitude = stamp_ns < 0 ? 0 - static_cast<std::uint64_t>(stamp_ns) : static_cast<std::uint64_t>(stamp_ns);
  return fmt::format_to_n(out, size, "{}{}.{:09d} {:.6f} {:.6f} {:.6f} {:.9f} {:.9f} {:.9f} {:.9f}\n",
                          stamp_ns < 0 ? "-" : "", magnitude / 1'000'000'000, magnitude % 1'000'000'000, t.x(), t.y(),
                          t.z(), q.x(), q.y(), q.z(), q.w());
}

constexpr std::size_t kLineSize = 1024;  // any finite double at {:.6f} fits

}  // namespace

void write_tum(std::ostream& out, const Trajectory& trajectory) {
  char line[kLineSize];
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    const auto stamp_ns = static_cast<std::int64_t>(std::llround(trajectory.stamps[i] * 1e9));
    const auto r = format_line(line, sizeof line, stamp_ns, trajectory.poses[i]);
    out.write(line, static_cast<std::streamsize>(std::min(r.size, sizeof line)));
  }
}

void write_tum(const std::filesystem::path& path, const Trajectory& trajectory) {
  std::ofstream out(path);
  if (!out) throw InputError(path.string(), "", "cannot open for writing");
  out << "# timestamp tx ty tz qx qy qz qw\n";
  write_tum(out, trajectory);
  if (!out) throw InputError(path.string(), "", "write failed");
}

TumWriter::TumWriter(const std::filesystem::path& path) {
  std::error_code error;
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path(), error);
  if (error) throw InputError(path.string(), "", "cannot create its folder: " + error.message());
  file_.reset(std::fopen(path.c_str(), "w"));
  if (!file_) throw InputError(path.string(), "", "cannot write the trajectory");
}

void TumWriter::write(std::int64_t stamp_ns, const Pose& pose) {
  if (!file_) return;
  char line[kLineSize];
  const auto r = format_line(line, sizeof line, stamp_ns, pose);
  std::fwrite(line, 1, std::min(r.size, sizeof line), file_.get());
}

bool TumWriter::flush() {
  if (!file_) return true;
  return std::fflush(file_.get()) == 0 && std::ferror(file_.get()) == 0;
}

namespace {

std::string at(const std::filesystem::path& path, std::size_t line) { return fmt::format("{}:{}", path.string(), line); }

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

// Whitespace-separated fields of `line` (runs of blanks are one separator).
void split_blanks(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_blank(line[i])) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
}

bool parse_finite(std::string_view field, double& value) {
  if (!field.empty() && field.front() == '+') field.remove_prefix(1);
  const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
  return ec == std::errc{} && end == field.data() + field.size() && !field.empty() && std::isfinite(value);
}

}  // namespace

Trajectory read_tum(std::istream& in, const std::filesystem::path& name) {
  Trajectory traj;
  std::string line;
  std::vector<std::string_view> fields;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    split_blanks(line, fields);
    if (fields.empty() || fields.front().front() == '#') continue;
    if (fields.size() != 8)
      throw InputError(at(name, number), "",
                       fmt::format("expected 8 fields (t x y z qx qy qz qw), found {}", fields.size()));
    double v[8];
    for (std::size_t k = 0; k < 8; ++k)
      if (!parse_finite(fields[k], v[k]))
        throw InputError(at(name, number), fmt::format("field {}", k + 1),
                         fmt::format("'{}' is not a finite number", fields[k]));
    if (!traj.stamps.empty() && v[0] < traj.stamps.back())
      throw InputError(at(name, number), "timestamp",
                       fmt::format("goes backwards: {:.9f} after {:.9f}", v[0], traj.stamps.back()));
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    const double norm = q.norm();
    if (norm < 1e-6) throw InputError(at(name, number), "quaternion", "has zero length");
    q.coeffs() /= norm;
    Pose pose = Pose::Identity();
    pose.linear() = q.toRotationMatrix();
    pose.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    traj.push_back(v[0], pose);
  }
  if (traj.empty()) throw InputError(name.string(), "", "contains no poses");
  return traj;
}

Trajectory read_tum(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), "", "cannot open for reading");
  return read_tum(in, path);
}

}  // namespace adit::slam
