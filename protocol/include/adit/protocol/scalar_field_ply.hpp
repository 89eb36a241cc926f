#pragma once
// A point cloud with named per-point scalar fields, as binary PLY: float x y z
// and one float property per field. CloudCompare lists each extra vertex
// property as a scalar field (colour scale, histogram, filter by value), so a
// deviation cloud opens there ready to read. Throws adit::InputError naming
// the file when it cannot be written.

#include <array>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace adit::protocol {

struct ScalarField {
  std::string name;              // a PLY property name: letters, digits, '_'
  std::span<const float> values; // one per point
};

void write_scalar_field_ply(const std::filesystem::path& file, std::span<const std::array<float, 3>> points,
                            std::span<const ScalarField> fields);

}  // namespace adit::protocol
