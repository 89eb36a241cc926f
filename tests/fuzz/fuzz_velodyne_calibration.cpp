// The Velodyne calibration YAML parser on arbitrary text: it either returns a
// calibration or throws adit::InputError; anything else is a bug.
// Seeds: ../shared/data/lidar/velodyne-*/*.yaml.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/velodyne.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto calibration = adit::drivers::parse_velodyne_calibration(text, "fuzz.yaml");
    if (calibration.lasers.empty()) __builtin_trap();
    for (const auto model : {adit::drivers::VelodyneModel::vlp16, adit::drivers::VelodyneModel::vlp32c}) {
      try {
        adit::drivers::VelodyneDecoder decoder(model, calibration);
      } catch (const adit::InputError&) {
      }
    }
  } catch (const adit::InputError&) {
  }
  return 0;
}
