#pragma once
// Software debounce (libgpiod v1 has none): a new level is accepted only
// after the raw line has stayed at it for `settle` with no further edge, the
// "integrating" debounce of Ganssle, "A Guide to Debouncing" (2004), in its
// edge-driven form. Pure: time comes from the caller.

#include <optional>

#include "adit/drivers/gpio/line.hpp"

namespace adit::drivers::gpio {

class Debouncer {
 public:
  explicit Debouncer(Nanoseconds settle = std::chrono::milliseconds(30), bool initial = false)
      : settle_(settle), stable_(initial), raw_(initial) {}

  void on_edge(const EdgeEvent& edge) {
    raw_ = edge.active;
    last_edge_ = edge.time;
    ++edges_;
  }
  // The new stable level, once, when the raw level has settled on a new value.
  std::optional<bool> poll(Nanoseconds now) {
    if (raw_ == stable_ || now - last_edge_ < settle_) return std::nullopt;
    stable_ = raw_;
    return stable_;
  }
  bool stable() const { return stable_; }
  std::uint64_t edges() const { return edges_; }  // raw edges seen, bounces included

 private:
  Nanoseconds settle_;
  bool stable_;
  bool raw_;
  Nanoseconds last_edge_{0};
  std::uint64_t edges_ = 0;
};

}  // namespace adit::drivers::gpio
