#include <chrono>

#include <gtest/gtest.h>

#include "adit/drivers/gpio/debounce.hpp"
#include "adit/drivers/gpio/fake_lines.hpp"
#include "adit/drivers/gpio/gpiod_lines.hpp"
#include "adit/drivers/gpio/led_pattern.hpp"
#include "adit/drivers/gpio/lidar_power.hpp"

namespace gpio = adit::drivers::gpio;
using std::chrono::milliseconds;
using std::chrono::seconds;

namespace {

// Feeds timed raw edges through a fake line into a debouncer polled every
// millisecond; returns (time in ms, stable level) of each accepted change.
std::vector<std::pair<int, bool>> debounce(const std::vector<std::pair<int, bool>>& edges, int until_ms, bool initial) {
  gpio::FakeInputLine line;
  for (const auto& [t, level] : edges) line.push(milliseconds(t), level);
  gpio::Debouncer d(milliseconds(20), initial);
  std::optional<gpio::EdgeEvent> pending = line.next_event(milliseconds(0));
  std::vector<std::pair<int, bool>> changes;
  for (int now = 0; now <= until_ms; ++now) {
    while (pending && pending->time <= milliseconds(now)) {
      d.on_edge(*pending);
      pending = line.next_event(milliseconds(0));
    }
    if (auto level = d.poll(milliseconds(now))) changes.emplace_back(now, *level);
  }
  return changes;
}

}  // namespace

TEST(Debouncer, BouncyPressAndReleaseGiveOneChangeEachAfterSettling) {
  // Press bouncing for 6 ms, held; release bouncing for 4 ms.
  const auto changes = debounce({{100, true}, {101, false}, {102, true}, {104, false}, {106, true},
                                 {300, false}, {301, true}, {303, false}, {304, false}},
                                400, false);
  ASSERT_EQ(changes.size(), 2U);
  EXPECT_EQ(changes[0], std::make_pair(126, true));   // 20 ms after the last bounce
  EXPECT_EQ(changes[1], std::make_pair(324, false));
}

TEST(Debouncer, GlitchShorterThanSettleIsIgnored) {
  gpio::Debouncer d(milliseconds(30));
  d.on_edge({milliseconds(100), true});
  d.on_edge({milliseconds(105), false});
  for (int now = 100; now < 200; ++now) EXPECT_FALSE(d.poll(milliseconds(now)).has_value());
  EXPECT_FALSE(d.stable());
}

TEST(LedPattern, StatesAreDistinguishableByDutyAndRate) {
  struct Shape {
    int on_ms = 0;
    int rises = 0;
  };
  const auto shape = [](gpio::PayloadState s) {
    Shape out;
    bool last = false;
    for (int t = 0; t < 4000; ++t) {
      const bool on = gpio::led_on(s, milliseconds(t));
      out.on_ms += on;
      out.rises += on && !last;
      last = on;
    }
    return out;
  };
  const Shape idle = shape(gpio::PayloadState::idle);
  const Shape mapping = shape(gpio::PayloadState::mapping);
  const Shape fault = shape(gpio::PayloadState::fault);
  const Shape starting = shape(gpio::PayloadState::starting);
  EXPECT_EQ(idle.on_ms, 200);
  EXPECT_EQ(idle.rises, 2);
  EXPECT_EQ(mapping.on_ms, 2000);
  EXPECT_EQ(mapping.rises, 4);
  EXPECT_EQ(fault.on_ms, 2000);
  EXPECT_EQ(fault.rises, 20);
  EXPECT_EQ(starting.on_ms, 4000);
}

TEST(LidarPower, OnAtStartOffAtShutdownAndCycledOnFault) {
  gpio::FakeOutputLine enable;
  gpio::PowerTiming timing;
  timing.off_time = seconds(2);
  timing.max_restarts = 2;
  timing.restart_window = seconds(60);
  gpio::LidarPower power(enable, timing);
  power.start(seconds(0));
  EXPECT_TRUE(power.powered());
  power.fault(seconds(10), false);  // e.g. packet loss: no restart needed
  EXPECT_TRUE(power.powered());
  power.fault(seconds(10), true);
  EXPECT_FALSE(power.powered());
  EXPECT_TRUE(power.cycling());
  power.update(seconds(11));
  EXPECT_FALSE(power.powered());
  power.update(seconds(12));
  EXPECT_TRUE(power.powered());
  power.fault(seconds(20), true);
  power.update(seconds(23));
  EXPECT_TRUE(power.powered());
  power.fault(seconds(30), true);  // third in the window: give up, stay off
  power.update(seconds(40));
  EXPECT_FALSE(power.powered());
  EXPECT_TRUE(power.latched());
  EXPECT_EQ(power.restarts(), 2U);
  power.start(seconds(100));
  EXPECT_TRUE(power.powered());
  EXPECT_FALSE(power.latched());
  power.shutdown(seconds(200));
  EXPECT_FALSE(power.powered());
  EXPECT_EQ(enable.writes(), (std::vector<bool>{true, false, true, false, true, false, true, false}));
}

TEST(GpiodBackend, MissingChipFailsNamingIt) {
  gpio::LineSpec spec;
  spec.chip = "gpiochip-adit-test";
  spec.offset = 17;
  try {
    auto line = gpio::open_gpiod_input(spec, "adit-test");
    FAIL() << "opened a chip that should not exist";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'gpiochip-adit-test'"), std::string::npos) << what;
    EXPECT_NE(what.find("line 17"), std::string::npos) << what;
  }
  spec.offset.reset();
  spec.name = "LIDAR_EN";
  EXPECT_THROW(gpio::open_gpiod_output(spec, "adit-test", false), std::runtime_error);
}
