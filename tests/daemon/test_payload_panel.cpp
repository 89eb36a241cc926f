#include <gtest/gtest.h>

#include "adit/daemon/payload_panel.hpp"
#include "adit/drivers/gpio/fake_lines.hpp"

namespace adit::daemon {
namespace {

using namespace std::chrono_literals;
using drivers::gpio::FakeInputLine;
using drivers::gpio::FakeOutputLine;
using drivers::gpio::PayloadState;

TEST(PayloadPanel, PowersTheLidarAndReportsOneDebouncedPressPerPush) {
  FakeInputLine button;
  FakeOutputLine led;
  FakeOutputLine power;
  PayloadPanel panel(button, led, power, 30ms, 0ms);
  EXPECT_TRUE(power.get());

  // A push with contact bounce: several edges within 10 ms, then held.
  button.push(100ms, true);
  button.push(102ms, false);
  button.push(104ms, true);
  EXPECT_FALSE(panel.tick(110ms, PayloadState::idle));  // still bouncing
  EXPECT_TRUE(panel.tick(140ms, PayloadState::idle));   // settled pressed: one press
  EXPECT_FALSE(panel.tick(190ms, PayloadState::idle));  // held: no repeat
  button.push(300ms, false);
  EXPECT_FALSE(panel.tick(340ms, PayloadState::idle));  // release is not a press
  button.push(500ms, true);
  EXPECT_TRUE(panel.tick(540ms, PayloadState::mapping));

  panel.shutdown(600ms);
  EXPECT_FALSE(power.get());
  EXPECT_FALSE(led.get());
}

TEST(PayloadPanel, TheLedFollowsTheStatePattern) {
  FakeInputLine button;
  FakeOutputLine led;
  FakeOutputLine power;
  PayloadPanel panel(button, led, power, 30ms, 0ms);
  // Mapping: 500 ms on, 500 ms off, counted from the change of state.
  panel.tick(1000ms, PayloadState::mapping);
  EXPECT_TRUE(led.get());
  panel.tick(1400ms, PayloadState::mapping);
  EXPECT_TRUE(led.get());
  panel.tick(1600ms, PayloadState::mapping);
  EXPECT_FALSE(led.get());
  // Fault: 100 ms flicker.
  panel.tick(2000ms, PayloadState::fault);
  EXPECT_TRUE(led.get());
  panel.tick(2150ms, PayloadState::fault);
  EXPECT_FALSE(led.get());
}

}  // namespace
}  // namespace adit::daemon
