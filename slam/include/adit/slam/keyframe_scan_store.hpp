#pragma once
// The loop closer's keyframes, bounded in RAM: each keyframe's scan and its
// place descriptor's bins (slam/scan_context.hpp). The newest `in_ram` stay
// in memory, older ones go to a folder, one file each, and are read back when
// a loop search or a candidate's submap needs them. Without a folder every
// keyframe stays in RAM (tests, tools).
//
// File (host byte order, written and read on the same payload):
//   "ADITKFS2" | uint64 point count n | uint32 descriptor rows r | uint32
//   columns c | r·c float32 bins (column by column) | n × (x, y, z) float32 |
//   uint64 FNV-1a of the bins' and the points' bytes.
// A file that is short, has another tag or size, or whose hash differs is
// damaged: a read says so and counts it, the caller goes on without it.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace adit::slam {

class KeyframeScanStore {
 public:
  explicit KeyframeScanStore(std::size_t in_ram = 200) : in_ram_(in_ram) {}

  // Before the first add(): older keyframes go to `folder` (created when needed).
  void spill_to(const std::filesystem::path& folder) { folder_ = folder; }

  // Keyframe size() gets `points` and `descriptor`; the oldest keyframe in
  // RAM beyond the window goes to its file (kept in RAM when it cannot be
  // written: counted).
  void add(std::vector<Eigen::Vector3f> points, Eigen::MatrixXf descriptor = {});
  // Fill `out` with keyframe k's scan, or its descriptor; false when k is
  // unknown or its file is missing or damaged (`last_error()` says which and why).
  bool read(std::size_t k, std::vector<Eigen::Vector3f>& out);
  bool read_descriptor(std::size_t k, Eigen::MatrixXf& out);

  std::size_t size() const { return keyframes_.size(); }
  std::size_t bytes_in_ram() const { return bytes_in_ram_; }
  std::size_t spilled() const { return spilled_; }
  std::size_t write_errors() const { return write_errors_; }
  std::size_t read_errors() const { return read_errors_; }
  const std::string& last_error() const { return last_error_; }
  std::filesystem::path file_of(std::size_t k) const;

 private:
  struct Slot {
    std::vector<Eigen::Vector3f> points;
    Eigen::MatrixXf descriptor;
    bool on_disk = false;
  };
  void spill(std::size_t k);
  // Reads keyframe k's file into `points` and `descriptor` (both checked).
  bool read_file(std::size_t k, std::vector<Eigen::Vector3f>& points, Eigen::MatrixXf& descriptor);

  std::size_t in_ram_;
  std::filesystem::path folder_;
  std::vector<Slot> keyframes_;
  // A file is read whole to check its hash: what the caller did not ask for lands here.
  std::vector<Eigen::Vector3f> scratch_points_;
  Eigen::MatrixXf scratch_descriptor_;
  std::size_t next_to_spill_ = 0;
  std::size_t bytes_in_ram_ = 0;
  std::size_t spilled_ = 0;
  std::size_t write_errors_ = 0;
  std::size_t read_errors_ = 0;
  std::string last_error_;
};

}  // namespace adit::slam
