#pragma once
// The loop closer's keyframe scans, bounded in RAM: the newest `in_ram`
// stay in memory, older ones go to a folder, one file each, and are read back
// when a loop candidate's submap needs them. Without a folder every scan
// stays in RAM (tests, tools).
//
// File (host byte order, written and read on the same payload):
//   "ADITKFS1" | uint64 point count n | n × (x, y, z) float32 | uint64 FNV-1a
//   of the points' bytes.
// A file that is short, has another tag or count, or whose hash differs is
// damaged: read() says so and counts it, the caller goes on without it.

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

  // Before the first add(): older scans go to `folder` (created when needed).
  void spill_to(const std::filesystem::path& folder) { folder_ = folder; }

  // Keyframe size() gets `points`; the oldest scan in RAM beyond the window
  // goes to its file (kept in RAM when it cannot be written: counted).
  void add(std::vector<Eigen::Vector3f> points);
  // Fills `out` with keyframe k's scan; false when k is unknown or its file
  // is missing or damaged (`last_error()` says which and why).
  bool read(std::size_t k, std::vector<Eigen::Vector3f>& out);

  std::size_t size() const { return scans_.size(); }
  std::size_t bytes_in_ram() const { return bytes_in_ram_; }
  std::size_t spilled() const { return spilled_; }
  std::size_t write_errors() const { return write_errors_; }
  std::size_t read_errors() const { return read_errors_; }
  const std::string& last_error() const { return last_error_; }
  std::filesystem::path file_of(std::size_t k) const;

 private:
  struct Slot {
    std::vector<Eigen::Vector3f> points;
    bool on_disk = false;
  };
  void spill(std::size_t k);

  std::size_t in_ram_;
  std::filesystem::path folder_;
  std::vector<Slot> scans_;
  std::size_t next_to_spill_ = 0;
  std::size_t bytes_in_ram_ = 0;
  std::size_t spilled_ = 0;
  std::size_t write_errors_ = 0;
  std::size_t read_errors_ = 0;
  std::string last_error_;
};

}  // namespace adit::slam
