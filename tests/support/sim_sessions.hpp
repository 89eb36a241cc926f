#pragma once
// Simulated sessions the daemon's tests share, generated once per build tree.

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "run_program.hpp"
#include "shared_data.hpp"

namespace adit::test {

// The session `adit sim OPTIONS` writes to binary_dir()/NAME, made once per
// build tree. It is written to a folder of this process's own and renamed
// into place whole: tests that run side by side (ctest -j) may make the same
// session at once; the first rename wins and the others drop their copies.
inline std::filesystem::path simulated_session(const std::string& name, const std::string& options) {
  const std::filesystem::path dir = binary_dir() / name;
  if (std::filesystem::exists(dir / "lidar.pcap")) return dir;
  const std::filesystem::path part = binary_dir() / fmt::format("{}.partial-{}", name, ::getpid());
  std::filesystem::create_directories(part.parent_path());
  std::filesystem::remove_all(part);
  const CommandRun sim = run_adit(fmt::format("sim {} --out {}", options, part.string()));
  EXPECT_EQ(sim.status, 0) << sim.output;
  std::error_code error;
  std::filesystem::rename(part, dir, error);
  if (error && !std::filesystem::exists(dir / "lidar.pcap")) {  // a folder left incomplete by an older run
    std::filesystem::remove_all(dir);
    std::filesystem::rename(part, dir, error);
  }
  if (error) std::filesystem::remove_all(part);  // another process's copy is in place
  return dir;
}

// A 12 s drive of the wheeled robot through the mine with a VLP-16, CAN wheels and accelerometer (seed 7).
inline std::filesystem::path mine_drive_12s() {
  return simulated_session("e2e-session-imu", "--scene mine --platform robot --sensor VLP-16 --duration 12 --seed 7");
}

// A 9 s walk through the mine with a hand-held OS1-64, its IMU packets in the capture (seed 1).
inline std::filesystem::path handheld_os1_9s() {
  return simulated_session("session-handheld-os1",
                           "--scene mine --platform handheld --sensor OS1-64 --duration 9 --seed 1");
}

}  // namespace adit::test
