#include "adit/drivers/gpio/lidar_power.hpp"

namespace adit::drivers::gpio {

LidarPower::LidarPower(OutputLine& enable, const PowerTiming& timing) : enable_(enable), timing_(timing) {}

void LidarPower::start(Nanoseconds now) {
  running_ = true;
  cycling_ = false;
  latched_ = false;
  restarts_in_window_ = 0;
  window_start_ = now;
  enable_.set(true);
}

void LidarPower::shutdown(Nanoseconds /*now*/) {
  running_ = false;
  cycling_ = false;
  enable_.set(false);
}

void LidarPower::fault(Nanoseconds now, bool needs_restart) {
  if (!running_ || !needs_restart || cycling_ || latched_) return;
  if (now - window_start_ > timing_.restart_window) {
    window_start_ = now;
    restarts_in_window_ = 0;
  }
  enable_.set(false);
  if (restarts_in_window_ >= timing_.max_restarts) {
    latched_ = true;  // restarting does not help: leave it off for a person to look at
    return;
  }
  ++restarts_in_window_;
  ++restarts_;
  cycling_ = true;
  cycle_end_ = now + timing_.off_time;
}

void LidarPower::update(Nanoseconds now) {
  if (cycling_ && now >= cycle_end_) {
    cycling_ = false;
    if (running_) enable_.set(true);
  }
}

}  // namespace adit::drivers::gpio
