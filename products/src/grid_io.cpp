#include "adit/products/grid_io.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::products {

Grid2d grid_of(const protocol::GridImage& image) {
  Grid2d grid;
  grid.resolution_m = image.resolution_m;
  grid.origin_x = image.origin_x;
  grid.origin_y = image.origin_y;
  grid.width = image.width;
  grid.height = image.height;
  grid.cells = image.cells;
  return grid;
}
namespace {

constexpr unsigned char kPgmOccupied = 0, kPgmFree = 254, kPgmUnknown = 205;

std::string read_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot open for reading");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

bool parse_number(std::string_view s, double& v) {
  s = trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc{} && end == s.data() + s.size() && !s.empty() && std::isfinite(v);
}

// The flat "key: value" YAML map_server writes and reads; origin as [x, y, yaw].
struct GridYaml {
  std::string image;
  double resolution = 0.0, origin[3] = {0, 0, 0};
  double occupied_thresh = 0.65, free_thresh = 0.196;  // map_saver's values
  bool has_resolution = false, has_origin = false, has_image = false;
};

GridYaml parse_yaml(std::string_view text, const std::string& name) {
  GridYaml y;
  std::size_t line_no = 0;
  while (!text.empty()) {
    ++line_no;
    const std::size_t eol = text.find('\n');
    std::string_view line = trim(text.substr(0, eol));
    text = eol == std::string_view::npos ? std::string_view{} : text.substr(eol + 1);
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) line = trim(line.substr(0, hash));
    if (line.empty()) continue;
    const std::size_t colon = line.find(':');
    const std::string where = fmt::format("{}:{}", name, line_no);
    if (colon == std::string_view::npos) throw InputError(where, "", fmt::format("expected 'key: value', got '{}'", line));
    const std::string key(trim(line.substr(0, colon)));
    const std::string_view value = trim(line.substr(colon + 1));
    if (key == "image") {
      y.image = std::string(value);
      if (y.image.size() >= 2 && (y.image.front() == '"' || y.image.front() == '\''))
        y.image = y.image.substr(1, y.image.size() - 2);
      y.has_image = !y.image.empty();
      if (!y.has_image) throw InputError(where, key, "is empty");
    } else if (key == "resolution") {
      if (!parse_number(value, y.resolution) || y.resolution <= 0.0)
        throw InputError(where, key, fmt::format("'{}' is not a positive number", value));
      y.has_resolution = true;
    } else if (key == "origin") {
      if (value.size() < 2 || value.front() != '[' || value.back() != ']')
        throw InputError(where, key, "expected [x, y, yaw]");
      std::string_view list = value.substr(1, value.size() - 2);
      for (int k = 0; k < 3; ++k) {
        const std::size_t comma = list.find(',');
        if ((k < 2) != (comma != std::string_view::npos) || !parse_number(list.substr(0, comma), y.origin[k]))
          throw InputError(where, key, "expected three numbers [x, y, yaw]");
        list = comma == std::string_view::npos ? std::string_view{} : list.substr(comma + 1);
      }
      if (y.origin[2] != 0.0) throw InputError(where, key, "a rotated grid (yaw != 0) is not supported");
      y.has_origin = true;
    } else if (key == "negate") {
      if (value != "0") throw InputError(where, key, "only negate: 0 is supported");
    } else if (key == "mode") {
      if (value != "trinary") throw InputError(where, key, "only mode: trinary is supported");
    } else if (key == "occupied_thresh" || key == "free_thresh") {
      double& v = key == "occupied_thresh" ? y.occupied_thresh : y.free_thresh;
      if (!parse_number(value, v) || v < 0.0 || v > 1.0)
        throw InputError(where, key, fmt::format("'{}' is not a number in 0 .. 1", value));
    } else {
      throw InputError(where, key, "unknown key");
    }
  }
  if (!y.has_image) throw InputError(name, "image", "missing");
  if (!y.has_resolution) throw InputError(name, "resolution", "missing");
  if (!y.has_origin) throw InputError(name, "origin", "missing");
  return y;
}

// P5 header: magic, width, height, maxval, separated by whitespace ('#' comments allowed).
std::size_t parse_pgm_header(std::string_view pgm, const std::string& name, int& width, int& height) {
  if (pgm.substr(0, 2) != "P5") throw InputError(name, "", "not a binary PGM (expected 'P5')");
  std::size_t i = 2;
  int values[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    while (i < pgm.size() && (std::isspace(static_cast<unsigned char>(pgm[i])) || pgm[i] == '#')) {
      if (pgm[i] == '#')
        while (i < pgm.size() && pgm[i] != '\n') ++i;
      else
        ++i;
    }
    const auto [end, ec] = std::from_chars(pgm.data() + i, pgm.data() + pgm.size(), values[k]);
    if (ec != std::errc{} || values[k] <= 0) throw InputError(name, "header", "bad width, height or maxval");
    i = static_cast<std::size_t>(end - pgm.data());
  }
  if (values[2] != 255) throw InputError(name, "maxval", fmt::format("{} (expected 255)", values[2]));
  if (i >= pgm.size() || !std::isspace(static_cast<unsigned char>(pgm[i])))
    throw InputError(name, "header", "no whitespace after maxval");
  width = values[0];
  height = values[1];
  if (width > 200000 || height > 200000) throw InputError(name, "header", "image larger than 200000 pixels a side");
  return i + 1;
}

}  // namespace

std::uintmax_t write_grid(const std::filesystem::path& stem, const Grid2d& grid) {
  std::filesystem::path pgm = stem, yaml = stem;
  pgm += ".pgm";
  yaml += ".yaml";
  {
    std::ofstream out(pgm, std::ios::binary);
    if (!out) throw InputError(pgm.string(), "", "cannot open for writing");
    out << fmt::format("P5\n# adit occupancy grid, {} m/cell\n{} {}\n255\n", grid.resolution_m, grid.width, grid.height);
    std::vector<char> row(static_cast<std::size_t>(grid.width));
    for (int r = grid.height - 1; r >= 0; --r) {  // the image's first row is the highest y
      for (int c = 0; c < grid.width; ++c) {
        const std::int8_t v = grid.at(c, r);
        row[static_cast<std::size_t>(c)] =
            static_cast<char>(v == kOccupied ? kPgmOccupied : v == kFree ? kPgmFree : kPgmUnknown);
      }
      out.write(row.data(), static_cast<std::streamsize>(row.size()));
    }
    if (!out) throw InputError(pgm.string(), "", "write failed");
  }
  {
    std::ofstream out(yaml);
    if (!out) throw InputError(yaml.string(), "", "cannot open for writing");
    out << fmt::format(
        "image: {}\nmode: trinary\nresolution: {}\norigin: [{:.6f}, {:.6f}, 0.0]\nnegate: 0\noccupied_thresh: 0.65\n"
        "free_thresh: 0.196\n",
        pgm.filename().string(), grid.resolution_m, grid.origin_x, grid.origin_y);
    if (!out) throw InputError(yaml.string(), "", "write failed");
  }
  return std::filesystem::file_size(pgm) + std::filesystem::file_size(yaml);
}

Grid2d parse_grid(std::string_view yaml, const std::string& yaml_name, std::string_view pgm,
                  const std::string& pgm_name) {
  const GridYaml y = parse_yaml(yaml, yaml_name);
  Grid2d g;
  g.resolution_m = y.resolution;
  g.origin_x = y.origin[0];
  g.origin_y = y.origin[1];
  const std::size_t data = parse_pgm_header(pgm, pgm_name, g.width, g.height);
  const std::size_t n = static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height);
  if (pgm.size() - data < n)
    throw InputError(pgm_name, "", fmt::format("truncated: {} pixels of {}", pgm.size() - data, n));
  g.cells.resize(n);
  for (int r = 0; r < g.height; ++r)
    for (int c = 0; c < g.width; ++c) {
      // map_server's trinary reading: p = (255 - v) / 255 against the thresholds.
      const auto v = static_cast<unsigned char>(pgm[data + static_cast<std::size_t>(g.height - 1 - r) * g.width + c]);
      const double p = (255.0 - v) / 255.0;
      g.at(c, r) = p > y.occupied_thresh ? kOccupied : p < y.free_thresh ? kFree : kUnknown;
    }
  return g;
}

Grid2d read_grid(const std::filesystem::path& yaml_file) {
  const std::string yaml = read_file(yaml_file);
  const GridYaml y = parse_yaml(yaml, yaml_file.string());
  const std::filesystem::path image = yaml_file.parent_path() / y.image;
  return parse_grid(yaml, yaml_file.string(), read_file(image), image.string());
}

}  // namespace adit::products
