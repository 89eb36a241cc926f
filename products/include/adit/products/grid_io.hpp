#pragma once
// The 2D grid's files in the ROS map_server / Nav2 format
// (https://wiki.ros.org/map_server#Map_format): a binary PGM image (P5,
// maxval 255, first row = highest y; occupied 0, free 254, unknown 205) and a
// YAML file naming it with resolution, origin [x, y, yaw], negate,
// occupied_thresh and free_thresh (map_saver's 0.65 and 0.196: 205 reads
// back as unknown), mode trinary.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "adit/products/grid_2d.hpp"
#include "adit/protocol/grid_mosaic.hpp"

namespace adit::products {

// Writes STEM.pgm and STEM.yaml; returns the bytes written (both files).
// Throws adit::InputError naming the file when it cannot be written.
std::uintmax_t write_grid(const std::filesystem::path& stem, const Grid2d& grid);

// The live grid's image (protocol::GridMosaic) as a grid: the same cells.
Grid2d grid_of(const protocol::GridImage& image);

// Reads a map_server YAML and the image it names (P5 PGM only; trinary,
// negate 0). Bad files throw adit::InputError naming the file, line and key.
Grid2d read_grid(const std::filesystem::path& yaml_file);
// The same from the files' contents; names are used in errors.
Grid2d parse_grid(std::string_view yaml, const std::string& yaml_name, std::string_view pgm,
                  const std::string& pgm_name);

}  // namespace adit::products
