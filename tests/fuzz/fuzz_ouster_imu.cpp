// libFuzzer target: any bytes as Ouster IMU packets, through
// drivers::decode_ouster_imu and the daemon's OusterImu (monitor, clock,
// mounting, hand-off). The input is cut into datagrams of 48 bytes (and a
// remainder of another size); each is pushed with an arbitrary receive time.
// Nothing may crash; every reading handed on must advance in time and be
// finite, and the counters must add up.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "adit/config/config.hpp"
#include "adit/daemon/ouster_imu.hpp"
#include "adit/drivers/lidar/ouster_packet.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace adit;
  drivers::OusterImuSample raw;
  (void)drivers::decode_ouster_imu(std::span<const std::uint8_t>(data, size), raw);

  drivers::OusterMetadata metadata;
  metadata.imu_to_sensor = {1, 0, 0, 6.253, 0, 1, 0, -11.775, 0, 0, 1, 7.645, 0, 0, 0, 1};
  config::Config config;
  config.imu.enabled = true;
  config.imu.source = config::ImuSource::ouster;
  config.imu.accel_range_mps2 = 4 * 9.80665;
  daemon::OusterImu imu(config, metadata, false);
  drivers::ClockOffsetEstimator clock;
  clock.add(0, 1'650'000'000'000'000'000);
  std::size_t offset = 0;
  std::int64_t host_ns = 1'650'000'000'000'000'000;
  while (offset < size) {
    const std::size_t n = std::min(size - offset, drivers::kOusterImuPacketBytes);
    host_ns += 10'000'000;
    imu.push(std::span<const std::uint8_t>(data + offset, n), host_ns, 0, clock);
    offset += n;
  }
  imu.close();
  imu.catch_up(1e30, {});
  const daemon::ImuStats& s = imu.imu_stats();
  if (s.samples.load() + s.count(daemon::ImuProblem::time_back) + s.count(daemon::ImuProblem::undecodable) +
          s.count(daemon::ImuProblem::unclocked) !=
      s.packets.load())
    std::abort();
  if (s.samples.load() > 0 && !std::isfinite(imu.history().latest())) std::abort();
  return 0;
}
