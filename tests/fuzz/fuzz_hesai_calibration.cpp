// libFuzzer: any text into the Hesai angle-correction CSV parser. It either
// returns a correction with equal-length columns or throws adit::InputError.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/hesai.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto c = adit::drivers::parse_hesai_angle_csv(text, "fuzz.csv");
    if (c.elevation_deg.empty() || c.elevation_deg.size() != c.azimuth_deg.size()) __builtin_trap();
  } catch (const adit::InputError&) {
  }
  return 0;
}
