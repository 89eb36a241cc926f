#pragma once
// The Ouster IMU packet, IMU profile LEGACY (firmware user manual 2.x, "IMU
// Data Format"): 48 bytes, little-endian, sent to UDP port 7503 at 100 Hz:
//   0   u64  system timestamp, ns (when the packet was formed)
//   8   u64  accelerometer read time, ns
//   16  u64  gyroscope read time, ns
//   24  3×f32  acceleration x y z, g
//   36  3×f32  angular velocity x y z, °/s
// in the IMU's axes (imu_to_sensor_transform places them in the sensor frame).
// The simulator stamps all three times with the sample's instant on the
// sensor clock (a real OS-1-128 capture, ../shared/data/lidar/ouster, reads
// the accelerometer 0.21 ms and the gyroscope 0.44 ms after the system time;
// the decoder reports the system time). Values are rounded to the real
// unit's steps as its packets show them: 1/2048 g and 1/32.768 °/s (16-bit
// registers at ±16 g and ±1000 °/s).

#include <array>
#include <cstdint>

#include "adit/drivers/lidar/ouster_packet.hpp"
#include "adit/sim/imu.hpp"

namespace adit::sim {

inline constexpr double kOusterImuAccelStepG = 1.0 / 2048.0;
inline constexpr double kOusterImuGyroStepDps = 1.0 / 32.768;

// `time_ns`: the sample's instant on the sensor clock (Unix ns).
std::array<std::uint8_t, drivers::kOusterImuPacketBytes> encode_ouster_imu_packet(const ImuSample& sample,
                                                                                    std::uint64_t time_ns);

}  // namespace adit::sim
