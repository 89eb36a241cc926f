// Fuzzes the loop closer's keyframe files (slam/keyframe_scan_store.hpp):
// any bytes in a keyframes/loops/NNNNNN.kfs (a damaged card, a torn write)
// must be read back or refused with a reason, without a crash and without
// allocating what a damaged count claims.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "adit/slam/keyframe_scan_store.hpp"

namespace {

// The run's scratch folder, removed when the fuzzer exits.
struct ScratchFolder {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("adit_fuzz_kfs_" + std::to_string(::getpid()));
  ~ScratchFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const ScratchFolder folder;
  adit::slam::KeyframeScanStore store(0);  // every scan to its file
  store.spill_to(folder.path);
  store.add({Eigen::Vector3f(1.0F, 2.0F, 3.0F)}, Eigen::MatrixXf::Ones(2, 3));
  if (store.spilled() != 1) return 0;  // the folder could not be written: nothing to read
  {
    std::ofstream file(store.file_of(0), std::ios::binary | std::ios::trunc);
    file.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  std::vector<Eigen::Vector3f> out;
  if (!store.read(0, out) && (store.last_error().empty() || !out.empty())) __builtin_trap();
  Eigen::MatrixXf bins;
  if (!store.read_descriptor(0, bins) && (store.last_error().empty() || bins.size() != 0)) __builtin_trap();
  return 0;
}
