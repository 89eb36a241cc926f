#pragma once
// One way for every program to turn errors into exit statuses and one line on
// stderr: bad input (InputError) exits 2, anything else unexpected exits 1.

#include <exception>
#include <string_view>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit {

template <typename Body>
int guarded_main(std::string_view program, Body&& body) {
  try {
    return body();
  } catch (const InputError& e) {
    fmt::print(stderr, "{}: error: {}\n", program, e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    fmt::print(stderr, "{}: fatal: {}\n", program, e.what());
    return kExitFailure;
  }
}

}  // namespace adit
