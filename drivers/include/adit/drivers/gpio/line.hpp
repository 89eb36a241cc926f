#pragma once
// Payload GPIO behind a small interface, so the logic above it runs against a
// fake in tests and libgpiod (v1 now, v2 later) on the payload.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

namespace adit::drivers::gpio {

using Nanoseconds = std::chrono::nanoseconds;

// Binds to one line of the `gpio:` config section.
struct LineSpec {
  std::string chip = "gpiochip0";  // name ("gpiochip0"), path ("/dev/gpiochip0") or label
  std::optional<unsigned> offset;  // line offset on the chip; or
  std::string name;                // line name from the device tree (used when offset is unset)
  bool active_low = false;         // logical "on" is a low level (button to ground, sinking LED)
};

struct EdgeEvent {
  Nanoseconds time{0};  // kernel timestamp of the edge (CLOCK_MONOTONIC on recent kernels)
  bool active = false;  // the line's logical level after the edge
};

class InputLine {
 public:
  virtual ~InputLine() = default;
  virtual bool active() = 0;  // logical level now
  // The next edge, waiting up to `timeout`; nullopt on timeout.
  virtual std::optional<EdgeEvent> next_event(Nanoseconds timeout) = 0;
  // A file descriptor that polls readable when an event is pending, or -1.
  virtual int event_fd() const = 0;
};

class OutputLine {
 public:
  virtual ~OutputLine() = default;
  virtual void set(bool active) = 0;  // logical level (active_low applied by the backend)
  virtual bool get() const = 0;       // the level last set
};

}  // namespace adit::drivers::gpio
