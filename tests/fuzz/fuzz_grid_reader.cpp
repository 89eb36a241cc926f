// Fuzzes the 2D grid reader (`adit eval grid` reads user files: a map_server
// YAML and the PGM it names). The input is the YAML, a NUL byte, then the
// PGM. Bad input must end in adit::InputError, nothing else.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "adit/common/error.hpp"
#include "adit/products/grid_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::size_t nul = bytes.find('\0');
  const std::string_view yaml = bytes.substr(0, nul);
  const std::string_view pgm = nul == std::string_view::npos ? std::string_view{} : bytes.substr(nul + 1);
  try {
    adit::products::parse_grid(yaml, "fuzz.yaml", pgm, "fuzz.pgm");
  } catch (const adit::InputError&) {
  }
  return 0;
}
