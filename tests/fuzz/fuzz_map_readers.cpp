// Fuzzes the readers `adit eval map` trusts with user files: map files (PLY,
// PCD, LAS), the scene mesh (PLY) and prior-map meshes (OBJ, STL). Bad input must end in adit::InputError,
// nothing else (no crash, no other exception, no sanitizer report).

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "adit/common/error.hpp"
#include "adit/protocol/map_import.hpp"
#include "adit/protocol/mesh_files.hpp"
#include "adit/protocol/ply_mesh.hpp"

namespace {

template <typename Read>
void expect_only_input_errors(Read&& read) {
  try {
    read();
  } catch (const adit::InputError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  using adit::protocol::MapFormat;
  for (const MapFormat f : {MapFormat::ply, MapFormat::pcd, MapFormat::las})
    expect_only_input_errors([&] { adit::protocol::read_map(bytes, f, "fuzz"); });
  expect_only_input_errors([&] { adit::protocol::read_ply_mesh(bytes, "fuzz.ply"); });
  expect_only_input_errors([&] { adit::protocol::read_obj_mesh(bytes, "fuzz.obj"); });
  expect_only_input_errors([&] { adit::protocol::read_stl_mesh(bytes, "fuzz.stl"); });
  return 0;
}
