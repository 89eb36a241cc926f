// Fuzzes the candump -L line parser. Every line must parse or be rejected
// with a reason; a parsed frame must survive writing and reading back.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "adit/drivers/can/candump.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace can = adit::drivers::can;
  std::string_view text(reinterpret_cast<const char*>(data), size);
  while (!text.empty()) {
    const std::size_t eol = text.find('\n');
    const std::string_view line = text.substr(0, eol);
    text.remove_prefix(eol == std::string_view::npos ? text.size() : eol + 1);
    can::Frame f;
    if (can::parse_candump_line(line, f) != can::LineError::none) continue;
    const std::string written = can::to_candump_line(f);
    can::Frame back;
    if (can::parse_candump_line(written, back) != can::LineError::none || !(back == f)) std::abort();
    if (can::to_candump_line(back) != written) std::abort();
  }
  return 0;
}
