#include "adit/sim/wheel_encoders.hpp"

#include <cmath>
#include <fstream>

#include <fmt/format.h>
#include <numbers>

#include "adit/common/error.hpp"
#include "adit/sim/hash_noise.hpp"

namespace adit::sim {
namespace {

constexpr std::uint64_t kSlipStream = 0x536C6970ULL;
constexpr std::uint64_t kCountStream = 0x436F756EULL;
constexpr double kSlipDuration = 0.3;
constexpr double kSlipGain = 0.3;

drivers::can::Frame tpdo(std::int64_t time_us, std::uint32_t id, std::int32_t counts) {
  drivers::can::Frame f;
  f.time_us = time_us;
  f.id = id;
  f.length = 4;
  f.set_interface_name("can0");
  const auto u = static_cast<std::uint32_t>(counts);
  for (int i = 0; i < 4; ++i) f.data[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(u >> (8 * i));
  return f;
}

}  // namespace

WheelTruth simulate_wheel_encoders(const BodyTrack& body, const WheelOptions& o, std::vector<drivers::can::Frame>& frames_out) {
  const double true_radius = o.radius_m * (1.0 + o.radius_error);
  const double counts_per_rad = o.counts_per_revolution / (2.0 * std::numbers::pi);
  const auto& samples = body.samples();
  const double dt = 1.0 / BodyTrack::kRate;
  // Slip events: in each second, with probability slips_per_minute/60, one wheel slips.
  const auto slip_gain = [&](double t, int wheel) {
    const auto second = static_cast<std::uint64_t>(t);
    if (uniform(o.seed, kSlipStream, 3 * second) >= o.slips_per_minute / 60.0) return 1.0;
    const int which = uniform(o.seed, kSlipStream, 3 * second + 1) < 0.5 ? 0 : 1;
    const double start = static_cast<double>(second) + (1.0 - kSlipDuration) * uniform(o.seed, kSlipStream, 3 * second + 2);
    return which == wheel && t >= start && t < start + kSlipDuration ? 1.0 + kSlipGain : 1.0;
  };
  WheelTruth truth;
  double left = 0.0, right = 0.0;  // wheel angles, rad
  std::size_t sample = 0;
  const auto frames = static_cast<std::uint64_t>(body.duration() * o.rate_hz);
  for (std::uint64_t k = 0; k <= frames; ++k) {
    const double t = static_cast<double>(k) / o.rate_hz;
    // Integrate the wheel rates over the trajectory samples up to t.
    while (sample + 1 < samples.size() && static_cast<double>(sample + 1) * dt <= t + 1e-12) {
      const BodySample& s = samples[sample];
      const double ts = static_cast<double>(sample) * dt;
      left += dt * slip_gain(ts, 0) * (s.speed_mps - s.yaw_rate_rps * o.track_m / 2.0) / true_radius;
      right += dt * slip_gain(ts, 1) * (s.speed_mps + s.yaw_rate_rps * o.track_m / 2.0) / true_radius;
      ++sample;
    }
    truth.time_s.push_back(t);
    truth.left_rad.push_back(left);
    truth.right_rad.push_back(right);
    const auto counts = [&](double angle, std::uint64_t index) {
      return static_cast<std::int32_t>(std::lround(angle * counts_per_rad + o.count_noise * gaussian(o.seed, kCountStream, index)));
    };
    const std::int64_t time_us = (o.start_time_ns + std::llround((t + o.time_offset_s) * 1e9)) / 1000;
    frames_out.push_back(tpdo(time_us, o.left_id, counts(left, 2 * k)));
    frames_out.push_back(tpdo(time_us + 150, o.right_id, counts(right, 2 * k + 1)));  // the second PDO follows on the bus
  }
  return truth;
}

void write_wheel_truth(const std::filesystem::path& file, const WheelTruth& truth, std::int64_t start_time_ns) {
  std::ofstream out(file, std::ios::trunc);
  out << "time,left_rad,right_rad\n";
  for (std::size_t i = 0; i < truth.time_s.size(); ++i) {
    const std::int64_t ns = start_time_ns + std::llround(truth.time_s[i] * 1e9);
    out << fmt::format("{}.{:09d},{:.9f},{:.9f}\n", ns / 1'000'000'000, ns % 1'000'000'000, truth.left_rad[i],
                       truth.right_rad[i]);
  }
  if (!out) throw InputError(file.string(), "", "could not write the wheel truth");
}

}  // namespace adit::sim
