#pragma once
// libgpiod v1 C++ backend (gpiod.hpp). Throws std::runtime_error naming the
// chip and the line when the chip cannot be opened or the line is missing or busy.

#include <memory>
#include <string>

#include "adit/drivers/gpio/line.hpp"

namespace adit::drivers::gpio {

// Requests both edges; the consumer label shows in `gpioinfo`.
std::unique_ptr<InputLine> open_gpiod_input(const LineSpec& spec, const std::string& consumer);
std::unique_ptr<OutputLine> open_gpiod_output(const LineSpec& spec, const std::string& consumer, bool initially_active);

}  // namespace adit::drivers::gpio
