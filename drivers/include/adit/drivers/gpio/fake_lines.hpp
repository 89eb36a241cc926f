#pragma once
// In-memory GPIO lines for tests: edges are pushed by the test, outputs
// record every level written.

#include <deque>
#include <vector>

#include "adit/drivers/gpio/line.hpp"

namespace adit::drivers::gpio {

class FakeInputLine final : public InputLine {
 public:
  void push(Nanoseconds time, bool active) { events_.push_back({time, active}); }
  bool active() override { return level_; }
  std::optional<EdgeEvent> next_event(Nanoseconds /*timeout*/) override {
    if (events_.empty()) return std::nullopt;
    const EdgeEvent e = events_.front();
    events_.pop_front();
    level_ = e.active;
    return e;
  }
  int event_fd() const override { return -1; }

 private:
  std::deque<EdgeEvent> events_;
  bool level_ = false;
};

class FakeOutputLine final : public OutputLine {
 public:
  void set(bool active) override {
    value_ = active;
    writes_.push_back(active);
  }
  bool get() const override { return value_; }
  const std::vector<bool>& writes() const { return writes_; }

 private:
  bool value_ = false;
  std::vector<bool> writes_;
};

}  // namespace adit::drivers::gpio
