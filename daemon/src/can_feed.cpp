#include "adit/daemon/can_feed.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Geometry>

#include "adit/common/clock.hpp"
#include "adit/daemon/imu_pose_feed.hpp"
#include "adit/common/error.hpp"
#include "adit/common/log.hpp"
#include "adit/daemon/can_imu_pairing.hpp"
#include "adit/daemon/extrinsics.hpp"
#include "adit/daemon/imu_monitor.hpp"
#include "adit/drivers/can/candump.hpp"
#include "adit/drivers/can/decoder.hpp"
#include "adit/drivers/can/signal.hpp"
#include "adit/drivers/can/socketcan.hpp"
#include "adit/drivers/can/units.hpp"
#include "adit/slam/wheel_odometry.hpp"

namespace adit::daemon {
namespace can = drivers::can;

std::vector<can::MessageSpec> can_messages_of(const config::Config& c) {
  if (!c.can.preset.empty())
    throw InputError("", "can.preset", "aditd reads wheel signals from can.dbc or can.signals; presets are for adit can-decode");
  std::vector<can::MessageSpec> messages;
  if (!c.can.dbc.empty()) messages = can::load_dbc(c.can.dbc).messages;
  for (const config::CanSignal& s : c.can.signals) {
    can::SignalSpec spec;
    spec.name = s.name;
    spec.start_bit = static_cast<unsigned>(s.start_bit);
    spec.length = static_cast<unsigned>(s.length);
    spec.byte_order = s.byte_order == config::ByteOrder::motorola ? can::ByteOrder::motorola : can::ByteOrder::intel;
    spec.is_signed = s.value_type == config::ValueType::signed_int;
    spec.type = s.value_type == config::ValueType::ieee_float
                    ? (s.length == 64 ? can::ValueType::float64 : can::ValueType::float32)
                    : can::ValueType::integer;
    spec.factor = s.factor;
    spec.offset = s.offset;
    spec.unit = s.unit;
    can::add_inline_signal(messages, s.id, s.extended, spec);
  }
  return messages;
}

namespace {

// The lowest and highest values a signal can carry (raw extremes × factor +
// offset, in SI units when the decoder converts); none for IEEE floats or a
// name not found. A reading at one of them is saturated.
std::pair<double, double> encoding_limits(const std::vector<can::MessageSpec>& messages, const std::string& name,
                                          bool convert) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (const can::MessageSpec& m : messages) {
    for (const can::SignalSpec& s : m.signals) {
      if (s.name != name && m.name + "." + s.name != name) continue;
      if (s.type != can::ValueType::integer || s.length == 0 || s.length > 63) return {-kInf, kInf};
      const double span = std::ldexp(1.0, static_cast<int>(s.length));
      const double raw_lo = s.is_signed ? -span / 2 : 0.0;
      const double raw_hi = s.is_signed ? span / 2 - 1 : span - 1;
      const double scale = convert ? can::si_conversion(s.unit).scale : 1.0;
      const double a = (raw_lo * s.factor + s.offset) * scale;
      const double b = (raw_hi * s.factor + s.offset) * scale;
      return {std::min(a, b), std::max(a, b)};
    }
  }
  return {-kInf, kInf};
}

}  // namespace

struct CanFeed::Impl {
  config::Config config;
  can::SignalDecoder decoder;
  std::size_t left = 0;
  std::size_t right = 0;
  slam::WheelOdometry odometry;
  std::optional<can::CandumpReader> log;
  std::optional<can::CanSocket> socket;
  HostClock host_clock;  // live frames' stamps
  can::BusMonitor bus;
  std::optional<can::CandumpWriter> recorder;
  std::vector<double> values;
  bool wheels = false;                 // wheel_odometry.enabled
  bool imu = false;                    // imu.enabled, source can
  bool gyro = false;                   // with the gyroscope's three signals
  std::array<std::size_t, 3> accel{};  // decoder slots of the accelerometer's x, y, z
  std::array<std::size_t, 3> rate{};   // and of the gyroscope's
  std::array<std::pair<double, double>, 6> limits{};  // each axis's encoding limits (ax ay az gx gy gz)
  Eigen::Matrix3d imu_to_body = Eigen::Matrix3d::Identity();
  CanImuPairing pairing{false};
  ImuMonitor monitor;

  static slam::WheelGeometry geometry_of(const config::WheelOdometrySection& w) {
    slam::WheelGeometry g;
    g.left_radius = w.left_radius_m;
    g.right_radius = w.right_radius_m;
    g.track_width = w.track_width_m;
    g.skid_factor = w.model == config::DriveModel::skid_steer ? 1.5 : 1.0;
    g.counts_per_revolution = w.counts_per_revolution;
    g.counter_bits = static_cast<unsigned>(w.counter_bits);
    return g;
  }

  static slam::WheelLimits limits_of(const config::WheelOdometrySection& w) {
    slam::WheelLimits l;
    l.max_acceleration = w.max_acceleration_mps2;
    l.max_slip_duration = w.max_slip_s;
    return l;
  }

  // The signals the feed decodes, with the config key that names each.
  // Wheels first (when enabled), then the accelerometer, then the gyroscope.
  static bool imu_on_can(const config::Config& c) { return c.imu.enabled && c.imu.source == config::ImuSource::can; }
  static bool gyro_on_can(const config::Config& c) { return imu_on_can(c) && !c.imu.gyro_x_signal.empty(); }
  static std::vector<std::pair<std::string, std::string>> wanted_signals(const config::Config& c) {
    std::vector<std::pair<std::string, std::string>> wanted;
    if (c.wheel_odometry.enabled) {
      wanted.emplace_back(c.wheel_odometry.left_signal, "wheel_odometry.left_signal");
      wanted.emplace_back(c.wheel_odometry.right_signal, "wheel_odometry.right_signal");
    }
    if (imu_on_can(c)) {
      wanted.emplace_back(c.imu.accel_x_signal, "imu.accel_x_signal");
      wanted.emplace_back(c.imu.accel_y_signal, "imu.accel_y_signal");
      wanted.emplace_back(c.imu.accel_z_signal, "imu.accel_z_signal");
    }
    if (gyro_on_can(c)) {
      wanted.emplace_back(c.imu.gyro_x_signal, "imu.gyro_x_signal");
      wanted.emplace_back(c.imu.gyro_y_signal, "imu.gyro_y_signal");
      wanted.emplace_back(c.imu.gyro_z_signal, "imu.gyro_z_signal");
    }
    return wanted;
  }

  // Signal values in SI units, unless the wheels read raw counts.
  static bool converts(const config::Config& c) {
    return !c.wheel_odometry.enabled || c.wheel_odometry.quantity != config::WheelQuantity::counts;
  }

  // The decoder of the wheel (and accelerometer) signals; an unknown signal is named by its config key.
  static can::SignalDecoder make_decoder(const config::Config& c) {
    const auto wanted = wanted_signals(c);
    std::vector<std::string> names;
    for (const auto& [name, key] : wanted) names.push_back(name);
    try {
      return can::SignalDecoder(can_messages_of(c), names, converts(c));
    } catch (const InputError& e) {
      for (const auto& [name, key] : wanted)
        if (e.key() == name) throw InputError(e.where(), key, e.reason());
      throw;
    }
  }

  Impl(const config::Config& c, ImuStats& imu_stats, HostClock clock)
      : config(c),
        decoder(make_decoder(c)),
        odometry(geometry_of(c.wheel_odometry), {}, limits_of(c.wheel_odometry)),
        host_clock(clock),
        wheels(c.wheel_odometry.enabled),
        imu(imu_on_can(c)),
        gyro(gyro_on_can(c)),
        pairing(gyro_on_can(c)),
        monitor(imu_stats, ImuLimits{c.imu.accel_range_mps2, c.imu.gyro_range_radps}) {
    const auto wanted = wanted_signals(c);
    const auto slot_of = [&](std::size_t i) {
      const auto& [name, key] = wanted[i];
      const int slot = decoder.slot(name);
      if (slot < 0) throw InputError("", key, "no such signal in can.dbc / can.signals");
      return static_cast<std::size_t>(slot);
    };
    const std::size_t first_imu = wheels ? 2 : 0;
    if (wheels) {
      left = slot_of(0);
      right = slot_of(1);
    }
    if (imu) {
      const std::vector<can::MessageSpec> messages = can_messages_of(c);
      for (std::size_t axis = 0; axis < 3; ++axis) {
        accel[axis] = slot_of(first_imu + axis);
        limits[axis] = encoding_limits(messages, wanted[first_imu + axis].first, converts(c));
        if (gyro) {
          rate[axis] = slot_of(first_imu + 3 + axis);
          limits[3 + axis] = encoding_limits(messages, wanted[first_imu + 3 + axis].first, converts(c));
        }
      }
      imu_to_body = rotation_of_rpy_deg(c.imu.rpy_deg);
    }
    values.resize(decoder.slot_count());
    if (c.can.source == config::CanSource::candump) {
      log.emplace(c.can.log);
    } else {
      can::SocketOptions options;
      options.interface = c.can.interface;
      try {
        socket.emplace(can::CanSocket::open(options));
      } catch (const std::runtime_error& e) {
        throw InputError(c.can.interface, "can.interface", e.what());
      }
    }
  }
};

CanFeed::CanFeed(const config::Config& config, HostClock clock)
    : impl_(std::make_unique<Impl>(config, imu_stats_, clock)),
      replay_(config.can.source == config::CanSource::candump),
      wheels_(impl_->wheels),
      imu_(impl_->imu),
      samples_(1024, replay_ ? Overflow::wait : Overflow::drop_oldest, [] { return CanSample{}; }) {
  mounting_.rotation = impl_->imu_to_body;
  mounting_.position_m = Eigen::Vector3d(config.imu.position_m[0], config.imu.position_m[1], config.imu.position_m[2]);
  imu_stats_.time_offset_s.store(config.imu.time_offset_s);
}

CanFeed::~CanFeed() { stop(); }

void CanFeed::start(const std::filesystem::path& record_file) {
  if (!record_file.empty()) impl_->recorder.emplace(record_file);
  thread_ = std::thread([this] { run(); });
}

void CanFeed::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (impl_->recorder) {
    try {
      impl_->recorder->flush();
    } catch (const std::exception& e) {
      log::error("CAN recording: {}", e.what());
    }
  }
}

void CanFeed::drain_into(slam::WheelHistory& history, double until_t, slam::ImuHistory* imu,
                         const std::function<bool()>& idle) {
  // A replay stops once both streams reach until_t, or a second past it
  // (an accelerometer that fell silent must not drain the whole log).
  const auto covered = [&] {
    if (wheels_ && history.latest() < until_t) return false;
    return imu == nullptr || !imu_ || imu->latest() >= until_t || drained_t_ >= until_t + 1.0;
  };
  const bool wait = replay_ && idle;
  while (!(replay_ && covered())) {
    CanSample* s = wait ? samples_.take_or_wait(idle) : samples_.take();
    if (s == nullptr) return;
    if (const auto* wheel = std::get_if<slam::WheelSample>(s)) {
      history.push(*wheel);
      drained_t_ = wheel->t;
    } else if (const auto* reading = std::get_if<slam::ImuSample>(s)) {
      if (imu != nullptr) imu->push(*reading);
      drained_t_ = reading->t;
    }
    samples_.release(s);
  }
}

void CanFeed::catch_up(double until_t, const std::function<bool()>& idle) {
  drain_into(wheel_history_, until_t, imu_ ? &imu_history_ : nullptr, idle);
}

bool CanFeed::hand_over(const CanSample& sample) {
  // A replay waits here while the odometry thread has not caught up.
  CanSample* out = samples_.acquire_or_wait([this] {
    beat_.beat();
    return !stop_.load(std::memory_order_relaxed);
  });
  if (out == nullptr) return false;
  *out = sample;
  samples_.publish(out);
  return true;
}

void CanFeed::run() {
  Impl& i = *impl_;
  const config::WheelOdometrySection& w = i.config.wheel_odometry;
  double value_left = NAN;
  double value_right = NAN;
  can::Frame frame;
  while (!stop_.load(std::memory_order_relaxed)) {
    beat_.beat();
    if (i.log) {
      if (!i.log->next(frame)) break;  // the replayed log has ended
    } else if (i.socket->read(frame, 100) != can::ReadResult::frame) {
      continue;
    } else {
      frame.time_us = i.host_clock.from_recent_realtime(frame.time_us * 1000) / 1000;
    }
    const std::int64_t received_mono_ns = monotonic_ns();  // the IMU-rate pose's latency counts from here
    stats_.frames.fetch_add(1, std::memory_order_relaxed);
    stats_.last_frame_us.store(frame.time_us, std::memory_order_relaxed);
    if (i.recorder) {
      i.recorder->write(frame);
      stats_.recorded.fetch_add(1, std::memory_order_relaxed);
    }
    const can::BusState before = i.bus.state();
    if (const can::BusState now = i.bus.on_frame(frame); now != before) {
      const can::BusCounters& c = i.bus.counters();
      stats_.bus_state.store(static_cast<int>(now), std::memory_order_relaxed);
      stats_.bus_off.store(c.bus_off, std::memory_order_relaxed);
      stats_.recoveries.store(c.recoveries, std::memory_order_relaxed);
    }
    if (frame.error) {
      stats_.error_frames.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    const can::DecodeResult r = i.decoder.decode(frame, i.values);
    if (r.status != can::DecodeStatus::decoded) continue;
    const auto written = [&](std::size_t slot) {
      return slot >= r.first && slot < r.first + r.count && !std::isnan(i.values[slot]);
    };
    // An accelerometer frame carries all three axes, a gyroscope frame too
    // (one frame may carry both).
    if (i.imu) {
      const std::uint64_t n = stats_.frames.load(std::memory_order_relaxed);
      const double t = 1e-6 * static_cast<double>(frame.time_us) - i.config.imu.time_offset_s;
      const auto read = [&](const std::array<std::size_t, 3>& slots, std::size_t first_axis, Eigen::Vector3d& v) {
        unsigned saturated = 0;
        for (std::size_t a = 0; a < 3; ++a) {
          v[static_cast<Eigen::Index>(a)] = i.values[slots[a]];
          const auto [lo, hi] = i.limits[first_axis + a];
          if (v[static_cast<Eigen::Index>(a)] <= lo || v[static_cast<Eigen::Index>(a)] >= hi) saturated |= 1U << a;
        }
        return saturated;
      };
      const auto all_written = [&](const std::array<std::size_t, 3>& slots) {
        return written(slots[0]) && written(slots[1]) && written(slots[2]);
      };
      CanImuPairing::Result results[2];
      if (all_written(i.accel)) {
        imu_stats_.packets.fetch_add(1, std::memory_order_relaxed);
        Eigen::Vector3d f;
        const unsigned saturated = read(i.accel, 0, f);
        results[0] = i.pairing.add_accel(t, f, saturated);
      }
      if (i.gyro && all_written(i.rate)) {
        imu_stats_.packets.fetch_add(1, std::memory_order_relaxed);
        Eigen::Vector3d w;
        const unsigned saturated = read(i.rate, 3, w);
        results[1] = i.pairing.add_gyro(t, w, saturated);
      }
      bool stopped = false;
      // A lone frame is reported at the frame that shows it lone.
      for (const CanImuPairing::Result& paired : results) {
        if (paired.gyro_dropped) i.monitor.report(ImuProblem::unpaired, n, 3);
        if (paired.accel_alone) i.monitor.report(ImuProblem::unpaired, n, 0);
        if (!paired.reading || !i.monitor.check(*paired.reading, n, paired.saturated_axes)) continue;
        slam::ImuSample body = *paired.reading;
        body.specific_force = i.imu_to_body * body.specific_force;
        body.angular_rate = i.imu_to_body * body.angular_rate;
        if (!hand_over(body)) {
          stopped = true;
          break;
        }
        stats_.imu_samples.fetch_add(1, std::memory_order_relaxed);
        imu_stats_.samples.fetch_add(1, std::memory_order_relaxed);
        if (body.has_gyro) imu_stats_.gyro_samples.fetch_add(1, std::memory_order_relaxed);
        imu_stats_.last_seen_realtime_ns.store(realtime_ns(), std::memory_order_relaxed);
        if (pose_feed_ != nullptr && body.has_gyro) pose_feed_->reading(body, received_mono_ns);
      }
      if (stopped) break;
    }
    if (!i.wheels) continue;
    // Left and right may come in separate frames: a sample is taken when both
    // have a value newer than the last sample.
    if (written(i.left)) value_left = i.values[i.left];
    if (written(i.right)) value_right = i.values[i.right];
    if (std::isnan(value_left) || std::isnan(value_right)) continue;
    const double t = 1e-6 * static_cast<double>(frame.time_us) - w.time_offset_s;
    slam::WheelStep step = slam::WheelStep::integrated;
    switch (w.quantity) {
      case config::WheelQuantity::counts:
        step = i.odometry.add_counts(t, static_cast<std::uint64_t>(static_cast<std::int64_t>(value_left)),
                                     static_cast<std::uint64_t>(static_cast<std::int64_t>(value_right)));
        break;
      case config::WheelQuantity::angular_speed: step = i.odometry.add_wheel_rates(t, value_left, value_right); break;
      case config::WheelQuantity::speed: step = i.odometry.add_speeds(t, value_left, value_right); break;
    }
    value_left = value_right = NAN;
    if (step != slam::WheelStep::integrated && step != slam::WheelStep::first)
      stats_.untrusted.fetch_add(1, std::memory_order_relaxed);
    stats_.slip_episodes.store(i.odometry.stats().slip_episodes, std::memory_order_relaxed);
    if (step == slam::WheelStep::time_backwards) continue;
    const bool held = step == slam::WheelStep::slip || step == slam::WheelStep::impossible;
    if (!hand_over(slam::WheelSample{t, i.odometry.pose(), i.odometry.distance(), step == slam::WheelStep::gap, held}))
      break;
    stats_.samples.fetch_add(1, std::memory_order_relaxed);
  }
  stats_.dropped.store(samples_.dropped());
  imu_stats_.dropped.store(samples_.dropped());  // wheels and IMU share the hand-off
  samples_.close();
  beat_.finished.store(true);
}

}  // namespace adit::daemon
