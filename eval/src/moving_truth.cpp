#include "adit/eval/moving_truth.hpp"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <unordered_map>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::eval {
namespace {

constexpr double kCell = 0.5;  // the track samples' plan grid

std::int64_t cell_key(double x, double y) {
  const auto ix = static_cast<std::int64_t>(std::floor(x / kCell));
  const auto iy = static_cast<std::int64_t>(std::floor(y / kCell));
  return ix * 4'000'003 + iy;
}

}  // namespace

std::vector<PersonSample> read_people_truth(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), "", "cannot open for reading");
  return read_people_truth(in, file.string());
}

std::vector<PersonSample> read_people_truth(std::istream& in, const std::string& file) {
  std::vector<PersonSample> out;
  std::string line;
  bool header = false;
  for (std::size_t n = 1; std::getline(in, line); ++n) {
    if (line.empty() || line[0] == '#') continue;
    if (!header) {
      if (line != "t,id,x,y,radius_m,height_m")
        throw InputError(fmt::format("{}:{}", file, n), "header", "expected t,id,x,y,radius_m,height_m");
      header = true;
      continue;
    }
    std::stringstream ss(line);
    std::string field;
    double v[6];
    int k = 0;
    while (std::getline(ss, field, ',')) {
      if (k == 6) break;
      try {
        std::size_t used = 0;
        v[k] = std::stod(field, &used);
        if (used != field.size() || !std::isfinite(v[k])) throw std::invalid_argument(field);
      } catch (const std::exception&) {
        throw InputError(fmt::format("{}:{}", file, n), fmt::format("field {}", k + 1),
                         fmt::format("'{}' is not a number", field));
      }
      ++k;
    }
    if (k != 6 || std::getline(ss, field, ','))
      throw InputError(fmt::format("{}:{}", file, n), "", "expected 6 fields");
    if (v[1] < 0.0 || v[1] > 1e6 || v[1] != std::floor(v[1]))
      throw InputError(fmt::format("{}:{}", file, n), "id", "must be a whole number from 0");
    if (v[4] <= 0.0 || v[5] <= 0.0)
      throw InputError(fmt::format("{}:{}", file, n), "radius_m", "radius and height must be positive");
    out.push_back({v[0], static_cast<int>(v[1]), v[2], v[3], v[4], v[5]});
  }
  if (!header) throw InputError(file, "header", "no header line");
  return out;
}

std::vector<std::uint8_t> label_people_points(std::span<const Eigen::Vector3d> points,
                                              std::span<const PersonSample> people, const MovingLabels& o) {
  std::unordered_map<std::int64_t, std::vector<std::size_t>> grid;
  double reach = 0.0;
  for (std::size_t i = 0; i < people.size(); ++i) {
    grid[cell_key(people[i].x, people[i].y)].push_back(i);
    reach = std::max(reach, people[i].radius_m + o.margin_m);
  }
  const int cells = static_cast<int>(std::ceil(reach / kCell));
  std::vector<std::uint8_t> label(points.size(), 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    const double z = p.z() - o.floor_z;
    if (z < o.floor_margin_m) continue;
    for (int dx = -cells; dx <= cells && !label[i]; ++dx)
      for (int dy = -cells; dy <= cells && !label[i]; ++dy) {
        const auto it = grid.find(cell_key(p.x() + dx * kCell, p.y() + dy * kCell));
        if (it == grid.end()) continue;
        for (const std::size_t s : it->second) {
          const PersonSample& q = people[s];
          const double r = q.radius_m + o.margin_m;
          if (z <= q.height_m + o.margin_m && std::hypot(p.x() - q.x, p.y() - q.y) <= r) {
            label[i] = 1;
            break;
          }
        }
      }
  }
  return label;
}

MovingScore score_moving(std::span<const Eigen::Vector3d> kept, std::span<const Eigen::Vector3d> removed,
                         std::span<const PersonSample> people, const MovingLabels& o) {
  MovingScore s;
  for (const std::uint8_t l : label_people_points(kept, people, o)) (l ? s.people_points : s.static_points)++;
  for (const std::uint8_t l : label_people_points(removed, people, o)) {
    (l ? s.people_points : s.static_points)++;
    (l ? s.people_removed : s.static_removed)++;
  }
  return s;
}

}  // namespace adit::eval
