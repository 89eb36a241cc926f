// libFuzzer target: the Ouster metadata parser must reject any input with an
// InputError (or accept it), never crash or throw anything else.
// Seeds: ../shared/data/lidar/ouster/metadata (and malformed/), as files.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/ouster_decoder.hpp"
#include "adit/drivers/lidar/ouster_metadata.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto m = adit::drivers::parse_ouster_metadata(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
    // Whatever the parser accepts must be safe to build a decoder from, as
    // long as it is of a size a sensor can have.
    if (static_cast<long>(m.columns_per_frame) * m.pixels_per_column <= 2048L * 128L) {
      const adit::drivers::OusterDecoder decoder(m);
      (void)decoder.max_points_per_packet();
    }
  } catch (const adit::InputError&) {
  }
  return 0;
}
