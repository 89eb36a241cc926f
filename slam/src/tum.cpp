#include "adit/slam/tum.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>

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

}  // namespace adit::slam
