#pragma once
// The status LED's patterns: a pure function of the payload state and the
// time since that state began, so they are easy to test and look the same on
// every payload.
//   idle     a short heartbeat: 100 ms on every 2 s
//   mapping  a steady slow blink: 500 ms on, 500 ms off
//   fault    a fast flicker: 100 ms on, 100 ms off
//   starting on steadily (sensors powering up)

#include <cstdint>

#include "adit/drivers/gpio/line.hpp"

namespace adit::drivers::gpio {

enum class PayloadState : std::uint8_t { idle, starting, mapping, fault };

bool led_on(PayloadState state, Nanoseconds since_state_change);

}  // namespace adit::drivers::gpio
