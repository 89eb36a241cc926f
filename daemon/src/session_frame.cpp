// The frame a session's exports are in (session_frame.hpp).
#include "adit/daemon/session_frame.hpp"

#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "adit/common/error.hpp"
#include "adit/daemon/durable_file.hpp"
#include "adit/slam/tum.hpp"

namespace adit::daemon {
namespace {

constexpr const char* kKey = "prior_from_odometry";
// The first line of a trajectory file moved into the prior's frame.
constexpr std::string_view kPlacedLine = "# frame: prior_map (prior_from_odometry of prior_frame.json applied)";

nlohmann::json rows_of(const Eigen::Isometry3d& t) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (int c = 0; c < 4; ++c) row.push_back(t.matrix()(r, c));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

void write_prior_frame(const std::filesystem::path& file, const Eigen::Isometry3d& prior_from_odometry) {
  const nlohmann::json j = {
      {kKey, rows_of(prior_from_odometry)},
      {"note", "the session's live poses and tiles are in the odometry frame; this places them in the prior map's, "
               "where its exports are (summary.json \"frame\")"}};
  write_durably(file, j.dump(2) + "\n");
}

Eigen::Isometry3d parse_prior_frame(std::string_view text, const std::string& name) {
  const nlohmann::json j = nlohmann::json::parse(text.begin(), text.end(), nullptr, false);
  if (!j.is_object() || !j.contains(kKey)) throw InputError(name, kKey, "missing (not a prior frame file)");
  const nlohmann::json& rows = j.at(kKey);
  if (!rows.is_array() || rows.size() != 4) throw InputError(name, kKey, "not a 4 x 4 matrix");
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    const nlohmann::json& row = rows[static_cast<std::size_t>(r)];
    if (!row.is_array() || row.size() != 4) throw InputError(name, kKey, "not a 4 x 4 matrix");
    for (int c = 0; c < 4; ++c) {
      const nlohmann::json& v = row[static_cast<std::size_t>(c)];
      if (!v.is_number() || !std::isfinite(v.get<double>())) throw InputError(name, kKey, "not finite numbers");
      m(r, c) = v.get<double>();
    }
  }
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  const bool rigid = (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() < 1e-6 && r.determinant() > 0.0 &&
                     m.row(3) == Eigen::RowVector4d(0, 0, 0, 1);
  if (!rigid) throw InputError(name, kKey, "not a rigid transform (rotation and translation)");
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(r).normalized().toRotationMatrix();
  t.translation() = m.topRightCorner<3, 1>();
  return t;
}

std::optional<Eigen::Isometry3d> read_prior_frame(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) {
    if (!std::filesystem::exists(file)) return std::nullopt;
    throw InputError(file.string(), "", "cannot be read");
  }
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parse_prior_frame(text, file.string());
}

bool place_trajectory_file(const std::filesystem::path& file, const Eigen::Isometry3d& frame) {
  std::ifstream in(file);
  if (!in) {
    if (!std::filesystem::exists(file)) return false;
    throw InputError(file.string(), "", "cannot be read");
  }
  std::string first;
  std::getline(in, first);
  if (first == kPlacedLine) return true;
  in.clear();
  in.seekg(0);
  slam::Trajectory t = slam::read_tum(in, file);
  for (slam::Pose& p : t.poses) p = frame * p;
  std::ostringstream out;
  out << kPlacedLine << "\n# timestamp tx ty tz qx qy qz qw\n";
  slam::write_tum(out, t);
  write_durably(file, out.str());
  return true;
}

nlohmann::json frame_summary(const std::optional<Eigen::Isometry3d>& prior_from_odometry) {
  if (!prior_from_odometry) return {{"name", "odometry"}};
  return {{"name", "prior_map"}, {kKey, rows_of(*prior_from_odometry)}};
}

}  // namespace adit::daemon
