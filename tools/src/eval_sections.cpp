// adit eval sections: the widths and heights on `adit products`'
// cross-sections (sections.csv) against the simulator's scene cut at the
// same places (eval/section_truth.hpp).

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/eval/section_truth.hpp"
#include "eval_commands.hpp"

namespace adit::tools {
namespace {

struct SectionRow {
  int id = 0;
  Eigen::Vector3d centre, across;
  double width = 0.0, height = 0.0;
};

std::vector<SectionRow> read_sections(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file, "", "cannot open for reading");
  std::vector<SectionRow> rows;
  std::string line;
  for (std::size_t n = 1; std::getline(in, line); ++n) {
    if (n == 1) {
      if (line.rfind("id,chainage_m,x,y,z,across_x,across_y", 0) != 0)
        throw InputError(fmt::format("{}:1", file), "header", "expected adit products' sections.csv header");
      continue;
    }
    if (line.empty()) continue;
    std::vector<double> v;
    std::stringstream ss(line);
    std::string field;
    while (std::getline(ss, field, ',')) {
      try {
        std::size_t used = 0;
        v.push_back(std::stod(field, &used));
        if (used != field.size()) throw std::invalid_argument(field);
      } catch (const std::exception&) {
        throw InputError(fmt::format("{}:{}", file, n), fmt::format("field {}", v.size() + 1),
                         fmt::format("'{}' is not a number", field));
      }
    }
    if (v.size() != 11) throw InputError(fmt::format("{}:{}", file, n), "", fmt::format("expected 11 fields, found {}", v.size()));
    rows.push_back({static_cast<int>(v[0]), {v[2], v[3], v[4]}, {v[5], v[6], 0.0}, v[9], v[10]});
  }
  return rows;
}

struct ErrorSummary {
  std::vector<double> e;
  void add(double x) {
    if (std::isfinite(x)) e.push_back(x);
  }
  double rms() const {
    double s = 0;
    for (double x : e) s += x * x;
    return e.empty() ? NAN : std::sqrt(s / e.size());
  }
  double worst() const {
    double w = 0;
    for (double x : e) w = std::max(w, std::abs(x));
    return e.empty() ? NAN : w;
  }
  double mean() const {
    double s = 0;
    for (double x : e) s += x;
    return e.empty() ? NAN : s / e.size();
  }
};

}  // namespace

void run_eval_sections(const SectionsEvalOptions& o) {
  const std::vector<SectionRow> rows = read_sections(o.sections);
  const std::vector<eval::Triangle> scene = scene_triangles(o.scene);
  const Eigen::Isometry3d world_from = world_from_map(o.ref, o.est);
  ErrorSummary width, height;
  nlohmann::json json_rows = nlohmann::json::array();
  if (!o.json) fmt::print("{:>4} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9}\n", "id", "width", "true", "error", "height", "true", "error");
  for (const SectionRow& r : rows) {
    const Eigen::Vector3d centre = world_from * r.centre;
    const Eigen::Vector3d across = world_from.linear() * r.across;
    const Eigen::Vector3d along(across.y(), -across.x(), 0.0);  // across is to the left of along
    const eval::SectionTruth t = eval::section_truth(scene, centre, along, o.width_at);
    const double ew = r.width - t.width_m, eh = r.height - t.height_m;
    width.add(ew);
    height.add(eh);
    if (o.json)
      json_rows.push_back({{"id", r.id}, {"width_m", r.width}, {"true_width_m", t.width_m}, {"height_m", r.height},
                           {"true_height_m", t.height_m}});
    else
      fmt::print("{:>4} {:>9.3f} {:>9.3f} {:>+9.3f} {:>9.3f} {:>9.3f} {:>+9.3f}\n", r.id, r.width, t.width_m, ew, r.height,
                 t.height_m, eh);
  }
  if (o.json) {
    fmt::print("{}\n", nlohmann::json{{"sections", json_rows},
                                      {"width", {{"n", width.e.size()}, {"mean_m", width.mean()}, {"rms_m", width.rms()}, {"worst_m", width.worst()}}},
                                      {"height", {{"n", height.e.size()}, {"mean_m", height.mean()}, {"rms_m", height.rms()}, {"worst_m", height.worst()}}}}
                           .dump(2));
    return;
  }
  fmt::print("width  error over {} sections: mean {:+.4f} m, rms {:.4f} m, worst {:.4f} m\n", width.e.size(), width.mean(),
             width.rms(), width.worst());
  fmt::print("height error over {} sections: mean {:+.4f} m, rms {:.4f} m, worst {:.4f} m\n", height.e.size(),
             height.mean(), height.rms(), height.worst());
}

}  // namespace adit::tools
