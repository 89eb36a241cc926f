#pragma once
// The header of a binary little-endian PLY file (Greg Turk's PLY polygon file
// format, as documented by Paul Bourke): elements, each with a count and
// scalar or list properties, then the binary data. Map files and scene meshes
// share it. Throws adit::InputError naming the file and the header line.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "adit/protocol/binary_scalar.hpp"

namespace adit::protocol {

struct PlyProperty {
  std::string name;
  std::string type;        // scalar type, or a list's item type
  std::string count_type;  // a list's count type; empty for a scalar
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  std::vector<PlyElement> elements;
  std::size_t data_offset = 0;  // first byte after "end_header\n"
};

PlyHeader parse_ply_header(std::string_view bytes, const std::string& file);

// The binary type of a PLY scalar type name (char/int8 ... double/float64); nullopt when unknown.
std::optional<Scalar> ply_scalar(std::string_view type);

// Bytes of a PLY scalar type; 0 when unknown.
std::size_t ply_type_size(std::string_view type);

// The little-endian scalar of PLY type `type` at p, as a double.
double read_ply_scalar(std::string_view type, const char* p);

}  // namespace adit::protocol
