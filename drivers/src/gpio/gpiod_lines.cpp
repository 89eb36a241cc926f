#include "adit/drivers/gpio/gpiod_lines.hpp"

#include <gpiod.hpp>

#include <stdexcept>
#include <system_error>

#include <fmt/format.h>

namespace adit::drivers::gpio {
namespace {

std::string describe(const LineSpec& spec) {
  return spec.offset ? fmt::format("GPIO chip '{}' line {}", spec.chip, *spec.offset)
                     : fmt::format("GPIO chip '{}' line '{}'", spec.chip, spec.name);
}

gpiod::line find(const LineSpec& spec, gpiod::chip& chip) {
  try {
    chip.open(spec.chip, gpiod::chip::OPEN_LOOKUP);
  } catch (const std::system_error& e) {
    throw std::runtime_error(fmt::format("{}: cannot open the chip: {}", describe(spec), e.what()));
  }
  try {
    gpiod::line line = spec.offset ? chip.get_line(*spec.offset) : chip.find_line(spec.name);
    if (!line) throw std::runtime_error("no such line");
    return line;
  } catch (const std::exception& e) {
    throw std::runtime_error(fmt::format("{}: {}", describe(spec), e.what()));
  }
}

gpiod::line_request request(const std::string& consumer, int type, const LineSpec& spec) {
  gpiod::line_request r;
  r.consumer = consumer;
  r.request_type = type;
  if (spec.active_low) r.flags |= gpiod::line_request::FLAG_ACTIVE_LOW;
  return r;
}

class GpiodInput final : public InputLine {
 public:
  GpiodInput(const LineSpec& spec, const std::string& consumer) : spec_(spec) {
    line_ = find(spec, chip_);
    try {
      line_.request(request(consumer, gpiod::line_request::EVENT_BOTH_EDGES, spec));
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("{}: cannot request edge events: {}", describe(spec), e.what()));
    }
  }
  bool active() override { return line_.get_value() != 0; }
  std::optional<EdgeEvent> next_event(Nanoseconds timeout) override {
    if (!line_.event_wait(timeout)) return std::nullopt;
    const gpiod::line_event e = line_.event_read();
    // The logical level is read back rather than derived from the edge type,
    // whose meaning under active-low differs between kernel versions; the
    // debouncer waits for the level to settle anyway.
    return EdgeEvent{e.timestamp, line_.get_value() != 0};
  }
  int event_fd() const override { return line_.event_get_fd(); }

 private:
  LineSpec spec_;
  gpiod::chip chip_;
  gpiod::line line_;
};

class GpiodOutput final : public OutputLine {
 public:
  GpiodOutput(const LineSpec& spec, const std::string& consumer, bool initially_active) : value_(initially_active) {
    line_ = find(spec, chip_);
    try {
      line_.request(request(consumer, gpiod::line_request::DIRECTION_OUTPUT, spec), initially_active ? 1 : 0);
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("{}: cannot request as output: {}", describe(spec), e.what()));
    }
  }
  void set(bool active) override {
    line_.set_value(active ? 1 : 0);
    value_ = active;
  }
  bool get() const override { return value_; }

 private:
  gpiod::chip chip_;
  gpiod::line line_;
  bool value_;
};

}  // namespace

std::unique_ptr<InputLine> open_gpiod_input(const LineSpec& spec, const std::string& consumer) {
  return std::make_unique<GpiodInput>(spec, consumer);
}

std::unique_ptr<OutputLine> open_gpiod_output(const LineSpec& spec, const std::string& consumer, bool initially_active) {
  return std::make_unique<GpiodOutput>(spec, consumer, initially_active);
}

}  // namespace adit::drivers::gpio
