#pragma once
// The payload's own controls (config `gpio:`): the start/stop button, the
// status LED and the LiDAR's power line, driven from aditd's main loop.
// A debounced press of the button toggles mapping (docs/CAN-AND-GPIO.md); the
// LED shows the session state with the patterns of drivers/gpio/led_pattern.hpp;
// the LiDAR is powered while aditd runs. Lines come through the small GPIO
// interface, so tests drive this with fakes and the payload with libgpiod.

#include <memory>

#include "adit/config/config.hpp"
#include "adit/drivers/gpio/debounce.hpp"
#include "adit/drivers/gpio/led_pattern.hpp"
#include "adit/drivers/gpio/lidar_power.hpp"
#include "adit/drivers/gpio/line.hpp"

namespace adit::daemon {

class PayloadPanel {
 public:
  using Nanoseconds = drivers::gpio::Nanoseconds;

  PayloadPanel(drivers::gpio::InputLine& button, drivers::gpio::OutputLine& led, drivers::gpio::OutputLine& power,
               Nanoseconds debounce, Nanoseconds now);

  // Every main-loop tick (≤ 50 ms): reads the button's edges, updates the LED
  // and the power line. True once per debounced press.
  bool tick(Nanoseconds now, drivers::gpio::PayloadState state);
  void shutdown(Nanoseconds now);

 private:
  drivers::gpio::InputLine& button_;
  drivers::gpio::OutputLine& led_;
  drivers::gpio::LidarPower power_;
  drivers::gpio::Debouncer debouncer_;
  drivers::gpio::PayloadState state_ = drivers::gpio::PayloadState::idle;
  Nanoseconds state_since_{0};
};

// The panel's lines on the payload, opened with libgpiod from the config;
// throws std::runtime_error naming the chip and line when one cannot be opened.
struct PayloadGpio {
  std::unique_ptr<drivers::gpio::InputLine> button;
  std::unique_ptr<drivers::gpio::OutputLine> led;
  std::unique_ptr<drivers::gpio::OutputLine> power;
};
PayloadGpio open_payload_gpio(const config::GpioSection& gpio);

}  // namespace adit::daemon
