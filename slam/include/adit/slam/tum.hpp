#pragma once
// Writing trajectories in the TUM RGB-D format, "t x y z qx qy qz qw" per
// line (https://cvg.cit.tum.de/data/datasets/rgbd-dataset/file_formats): the
// one writer of the project (the daemon's trajectories and keyframes, the
// simulator's truth, the tools' outputs) and the one TUM reader (eval/'s
// trajectory readers and the session products read through it). A stamp is
// written from whole nanoseconds ("1767225600.012345678": a double holds Unix
// times to 0.2 µs only), positions to 1 µm, the quaternion to 9 decimals.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iosfwd>
#include <memory>

#include "adit/slam/trajectory.hpp"

namespace adit::slam {

// Stamps in seconds, rounded to the nanosecond.
void write_tum(std::ostream& out, const Trajectory& trajectory);
// With a "# timestamp tx ty tz qx qy qz qw" header; throws adit::InputError naming the file.
void write_tum(const std::filesystem::path& path, const Trajectory& trajectory);

// Reads "t x y z qx qy qz qw" lines ('#' comments and blank lines skipped;
// quaternions renormalised, files carry rounded ones). A malformed line, a
// zero quaternion, a time going backwards or no pose at all throws
// adit::InputError naming "file:line"; `name` is the file named in errors.
Trajectory read_tum(std::istream& in, const std::filesystem::path& name);
Trajectory read_tum(const std::filesystem::path& path);

// A TUM file written a line at a time as poses arrive (buffered stdio: no
// allocation per line). Default-constructed, it is closed and writes nothing.
class TumWriter {
 public:
  TumWriter() = default;
  // Creates the parent folders; throws adit::InputError naming the file.
  explicit TumWriter(const std::filesystem::path& path);
  bool is_open() const { return file_ != nullptr; }
  void write(std::int64_t stamp_ns, const Pose& pose);
  // False when a write failed (disk full); the writer never throws after opening.
  bool flush();

 private:
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, Closer> file_;
};

}  // namespace adit::slam
