#include "adit/daemon/payload_panel.hpp"

#include "adit/drivers/gpio/gpiod_lines.hpp"

namespace adit::daemon {

using drivers::gpio::PayloadState;

PayloadPanel::PayloadPanel(drivers::gpio::InputLine& button, drivers::gpio::OutputLine& led,
                           drivers::gpio::OutputLine& power, Nanoseconds debounce, Nanoseconds now)
    : button_(button), led_(led), power_(power), debouncer_(debounce, button.active()), state_since_(now) {
  power_.start(now);
  led_.set(drivers::gpio::led_on(state_, Nanoseconds{0}));
}

bool PayloadPanel::tick(Nanoseconds now, PayloadState state) {
  while (const auto edge = button_.next_event(Nanoseconds{0})) debouncer_.on_edge(*edge);
  const auto level = debouncer_.poll(now);
  if (state != state_) {
    state_ = state;
    state_since_ = now;
  }
  led_.set(drivers::gpio::led_on(state_, now - state_since_));
  power_.update(now);
  return level.has_value() && *level;  // pressed, not released
}

void PayloadPanel::shutdown(Nanoseconds now) {
  led_.set(false);
  power_.shutdown(now);
}

namespace {
drivers::gpio::LineSpec spec_of(const config::GpioSection& gpio, const config::GpioLine& line) {
  drivers::gpio::LineSpec spec;
  spec.chip = gpio.chip;
  if (line.offset >= 0) spec.offset = static_cast<unsigned>(line.offset);
  spec.name = line.name;
  spec.active_low = line.active_low;
  return spec;
}
}  // namespace

PayloadGpio open_payload_gpio(const config::GpioSection& gpio) {
  PayloadGpio out;
  out.button = drivers::gpio::open_gpiod_input(spec_of(gpio, gpio.button), "aditd-button");
  out.led = drivers::gpio::open_gpiod_output(spec_of(gpio, gpio.status_led), "aditd-led", false);
  out.power = drivers::gpio::open_gpiod_output(spec_of(gpio, gpio.lidar_power), "aditd-lidar-power", false);
  return out;
}

}  // namespace adit::daemon
