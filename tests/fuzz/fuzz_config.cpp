// Fuzzes the configuration loader: any input must either load or be rejected
// with adit::InputError; any other exception or crash is a bug.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "adit/common/error.hpp"
#include "adit/config/load.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    adit::config::parse_config(text, "fuzz.yaml", "/");
  } catch (const adit::InputError&) {
  }
  return 0;
}
