#include "adit/protocol/scalar_field_ply.hpp"

#include <cstring>
#include <fstream>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::protocol {

void write_scalar_field_ply(const std::filesystem::path& file, std::span<const std::array<float, 3>> points,
                            std::span<const ScalarField> fields) {
  for (const ScalarField& f : fields) {
    if (f.values.size() != points.size())
      throw InputError(file.string(), f.name, fmt::format("{} values for {} points", f.values.size(), points.size()));
    if (f.name.empty() || f.name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") != std::string::npos)
      throw InputError(file.string(), f.name, "not a PLY property name");
  }
  std::string header = fmt::format("ply\nformat binary_little_endian 1.0\ncomment adit scalar fields\nelement vertex {}\n"
                                   "property float x\nproperty float y\nproperty float z\n",
                                   points.size());
  for (const ScalarField& f : fields) header += fmt::format("property float {}\n", f.name);
  header += "end_header\n";
  const std::size_t stride = 4 * (3 + fields.size());
  std::vector<char> body(points.size() * stride);
  for (std::size_t i = 0; i < points.size(); ++i) {
    char* out = body.data() + i * stride;
    std::memcpy(out, points[i].data(), 12);
    for (std::size_t k = 0; k < fields.size(); ++k) std::memcpy(out + 12 + 4 * k, &fields[k].values[i], 4);
  }
  std::ofstream out(file, std::ios::binary);
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(body.data(), static_cast<std::streamsize>(body.size()));
  if (!out.flush()) throw InputError(file.string(), "", "cannot be written");
}

}  // namespace adit::protocol
