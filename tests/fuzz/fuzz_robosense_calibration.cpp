// libFuzzer: any text into the RoboSense angle CSV parser: 16 rows back, or adit::InputError.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/robosense.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto a = adit::drivers::parse_robosense_angle_csv(text, "fuzz.csv");
    if (a.elevation_deg.size() != 16 || a.azimuth_deg.size() != 16) __builtin_trap();
  } catch (const adit::InputError&) {
  }
  return 0;
}
