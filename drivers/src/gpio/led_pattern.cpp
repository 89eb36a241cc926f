#include "adit/drivers/gpio/led_pattern.hpp"

namespace adit::drivers::gpio {
namespace {

using std::chrono::milliseconds;

bool blink(Nanoseconds t, milliseconds on, milliseconds period) {
  if (t.count() < 0) t = Nanoseconds{0};
  return t % period < on;
}

}  // namespace

bool led_on(PayloadState state, Nanoseconds t) {
  switch (state) {
    case PayloadState::idle: return blink(t, milliseconds(100), milliseconds(2000));
    case PayloadState::starting: return true;
    case PayloadState::mapping: return blink(t, milliseconds(500), milliseconds(1000));
    case PayloadState::fault: return blink(t, milliseconds(100), milliseconds(200));
  }
  return false;
}

}  // namespace adit::drivers::gpio
