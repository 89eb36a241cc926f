// adit eval endpoint: end-to-end drift against a total-station delta.

#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/eval/endpoint.hpp"
#include "adit/eval/trajectory_io.hpp"
#include "eval_commands.hpp"

namespace adit::tools {
namespace {

// "DX,DY,DZ" in metres.
Eigen::Vector3d parse_delta(const std::string& text) {
  Eigen::Vector3d v;
  std::size_t start = 0;
  for (int k = 0; k < 3; ++k) {
    const std::size_t end = k < 2 ? text.find(',', start) : text.size();
    if (end == std::string::npos) break;
    const std::string field = text.substr(start, end - start);
    std::size_t used = 0;
    try {
      v(k) = std::stod(field, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || field.find_first_not_of(" \t", used) != std::string::npos || !std::isfinite(v(k)))
      throw InputError("", "--true-delta", fmt::format("'{}' is not a number (expected DX,DY,DZ in metres)", field));
    if (k == 2) return v;
    start = end + 1;
  }
  throw InputError("", "--true-delta", fmt::format("'{}': expected three numbers DX,DY,DZ in metres", text));
}

}  // namespace

void run_eval_endpoint(const EndpointEvalOptions& o) {
  const Eigen::Vector3d true_delta = parse_delta(o.true_delta);
  const eval::TrajectoryFormat f =
      o.format == "auto" ? eval::detect_trajectory_format(o.est) : *eval::parse_trajectory_format(o.format);
  std::optional<std::filesystem::path> times;
  if (!o.times.empty()) times = o.times;
  const slam::Trajectory traj = eval::read_trajectory(o.est, f, times);
  if (traj.size() < 2) throw InputError(o.est, "", "needs at least 2 poses for a start and an end");

  const eval::EndpointDrift d = eval::endpoint_drift(traj.poses, true_delta);
  const auto vec = [](const Eigen::Vector3d& v) { return nlohmann::json{v.x(), v.y(), v.z()}; };
  if (o.json) {
    const nlohmann::json j{{"trajectory", o.est},
                           {"poses", traj.size()},
                           {"true_delta_m", vec(d.true_delta)},
                           {"estimated_delta_m", vec(d.estimated_delta)},
                           {"error_m", vec(d.error)},
                           {"drift_m", d.drift},
                           {"length_m", d.length},
                           {"drift_rate", d.rate}};
    fmt::print("{}\n", j.dump(2));
    return;
  }
  fmt::print("trajectory        {} ({} poses)\n", o.est, traj.size());
  fmt::print("{:<18}{:>12} {:>12} {:>12}\n", "", "DX (m)", "DY (m)", "DZ (m)");
  const auto row = [](const char* name, const Eigen::Vector3d& v) {
    fmt::print("{:<18}{:>12.4f} {:>12.4f} {:>12.4f}\n", name, v.x(), v.y(), v.z());
  };
  row("true (survey)", d.true_delta);
  row("estimated", d.estimated_delta);
  row("true - estimated", d.error);
  fmt::print("drift dT          {:.4f} m\n", d.drift);
  fmt::print("path length L     {:.3f} m\n", d.length);
  fmt::print("drift rate dT/L   {:.4f} % ({:.0f} ppm)\n", 100.0 * d.rate, 1e6 * d.rate);
}

}  // namespace adit::tools
