#pragma once
// The adit configuration that replays a simulated session: the pcap and the
// candump log as sources, the sensor's calibration, the extrinsics and the
// wheel model as CONFIGURED (the nominal radius: the simulated wheels' true
// radius differs, as on a real robot), the IMU (on CAN: its six signals; an
// Ouster's: source ouster) with its mount, clock offset and noise model as
// simulated. Paths are relative to the file.

#include <filesystem>
#include <string>

#include <Eigen/Geometry>

#include "adit/sim/session.hpp"
#include "adit/sim/imu.hpp"
#include "adit/sim/wheel_encoders.hpp"

namespace adit::sim {

// Throws adit::InputError when the file cannot be written.
void write_session_config(const std::filesystem::path& file, const SimOptions& options,
                          const std::string& calibration_file, const WheelOptions& wheels, const ImuOptions& imu,
                          SimImuSource imu_source, const Eigen::Isometry3d& extrinsics);

}  // namespace adit::sim
