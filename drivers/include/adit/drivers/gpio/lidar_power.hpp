#pragma once
// The LiDAR's power enable line: on at start, off at shutdown, and power
// cycled (off, wait, on) on a fault that needs a sensor restart. Restarts are
// limited: after max_restarts within restart_window the power stays off and
// the fault is latched until the next start(). Time comes from the caller.

#include <cstdint>

#include "adit/drivers/gpio/line.hpp"

namespace adit::drivers::gpio {

// Binds to `gpio: lidar_power:` timing keys.
struct PowerTiming {
  Nanoseconds off_time = std::chrono::seconds(3);          // how long the sensor stays unpowered in a cycle
  unsigned max_restarts = 3;                               // power cycles allowed per window
  Nanoseconds restart_window = std::chrono::minutes(10);
};

class LidarPower {
 public:
  LidarPower(OutputLine& enable, const PowerTiming& timing = {});

  void start(Nanoseconds now);     // power on; clears a latched fault
  void shutdown(Nanoseconds now);  // power off
  // A sensor fault; with needs_restart the power is cycled (if restarts are left).
  void fault(Nanoseconds now, bool needs_restart);
  void update(Nanoseconds now);    // call periodically: ends a power cycle

  bool powered() const { return enable_.get(); }
  bool cycling() const { return cycling_; }
  bool latched() const { return latched_; }  // gave up restarting
  std::uint64_t restarts() const { return restarts_; }

 private:
  OutputLine& enable_;
  PowerTiming timing_;
  bool cycling_ = false;
  bool latched_ = false;
  bool running_ = false;
  Nanoseconds cycle_end_{0};
  Nanoseconds window_start_{0};
  unsigned restarts_in_window_ = 0;
  std::uint64_t restarts_ = 0;
};

}  // namespace adit::drivers::gpio
