// libFuzzer target: any sequence of CAN IMU frames through the daemon's
// pairing (CanImuPairing) and checks (ImuMonitor): each 8 input bytes are one
// frame: kind (even: accelerometer, odd: gyroscope), a signed time step in
// 10 µs (time may go back), three int16 values (at the encoding's limits:
// saturated). Nothing may crash; readings the monitor keeps advance in time,
// a reading carries a gyroscope only when one was paired, and every frame is
// accounted for.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "adit/daemon/can_imu_pairing.hpp"
#include "adit/daemon/imu_monitor.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace adit::daemon;
  if (size < 1) return 0;
  ImuStats stats;
  ImuMonitor monitor(stats, ImuLimits{39.2, 8.7});
  CanImuPairing pairing((data[0] & 1U) != 0);
  double t = 1000.0;
  double last_kept = -1e300;
  std::uint64_t readings = 0;
  std::uint64_t gyros = 0;
  for (std::size_t off = 1; off + 8 <= size; off += 8) {
    const std::uint8_t* f = data + off;
    std::int8_t step = 0;
    std::memcpy(&step, f + 1, 1);
    t += 1e-5 * step;
    std::int16_t v[3];
    std::memcpy(v, f + 2, 6);
    unsigned saturated = 0;
    for (int a = 0; a < 3; ++a)
      if (v[a] == INT16_MAX || v[a] == INT16_MIN) saturated |= 1U << a;
    const bool gyro = (f[0] & 1U) != 0;
    const Eigen::Vector3d value(v[0] * (gyro ? 0.0002 : 0.001), v[1] * (gyro ? 0.0002 : 0.001),
                                v[2] * (gyro ? 0.0002 : 0.001));
    const CanImuPairing::Result r = gyro ? pairing.add_gyro(t, value, saturated) : pairing.add_accel(t, value, saturated);
    if (gyro) ++gyros;
    if (!r.reading) continue;
    if (r.reading->has_gyro && !pairing.gyro()) std::abort();
    ++readings;
    if (monitor.check(*r.reading, off / 8)) {
      if (!(r.reading->t > last_kept)) std::abort();
      last_kept = r.reading->t;
    }
  }
  if (readings > size / 8) std::abort();
  if (!pairing.gyro() && gyros > 0 && readings > size / 8 - gyros) std::abort();
  return 0;
}
