#include "adit/products/session_join_files.hpp"

#include <algorithm>
#include <fstream>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "adit/common/error.hpp"
#include "adit/protocol/map_export.hpp"
#include "adit/protocol/map_import.hpp"
#include "adit/slam/prior_map.hpp"
#include "adit/slam/tum.hpp"

namespace adit::products {
namespace {

nlohmann::json pose_json(const Eigen::Isometry3d& t) {
  const Eigen::Quaterniond q(t.linear());
  return {t.translation().x(), t.translation().y(), t.translation().z(), q.x(), q.y(), q.z(), q.w()};
}

std::vector<Eigen::Vector3f> xyz(const std::vector<protocol::MapPoint>& map, const Eigen::Isometry3d& t) {
  std::vector<Eigen::Vector3f> out(map.size());
  for (std::size_t i = 0; i < map.size(); ++i) out[i] = (t * Eigen::Vector3d(map[i].x, map[i].y, map[i].z)).cast<float>();
  return out;
}

struct SessionFiles {
  std::vector<protocol::MapPoint> map;
  slam::Trajectory trajectory;
};

SessionFiles read_session(const std::filesystem::path& dir) {
  SessionFiles s{protocol::read_map(dir / "map.ply"), slam::read_tum(dir / "trajectory.tum")};
  if (s.map.empty()) throw InputError((dir / "map.ply").string(), "", "the map is empty");
  if (s.trajectory.empty()) throw InputError((dir / "trajectory.tum").string(), "", "the trajectory is empty");
  return s;
}

// Both sessions in the stored one's frame: the maps together, the paths in time order.
void write_joined(const std::filesystem::path& out, const SessionFiles& stored, const SessionFiles& joining,
                  const Eigen::Isometry3d& stored_from_new) {
  std::filesystem::create_directories(out);
  std::vector<protocol::MapPoint> map;
  map.reserve(stored.map.size() + joining.map.size());
  map.insert(map.end(), stored.map.begin(), stored.map.end());
  for (protocol::MapPoint p : joining.map) {
    const Eigen::Vector3d q = stored_from_new * Eigen::Vector3d(p.x, p.y, p.z);
    p.x = q.x();
    p.y = q.y();
    p.z = q.z();
    map.push_back(p);
  }
  protocol::write_map(out / "map.ply", protocol::MapFormat::ply, map);
  std::vector<std::pair<double, Eigen::Isometry3d>> all;
  for (std::size_t i = 0; i < stored.trajectory.size(); ++i) all.emplace_back(stored.trajectory.stamps[i], stored.trajectory.poses[i]);
  for (std::size_t i = 0; i < joining.trajectory.size(); ++i)
    all.emplace_back(joining.trajectory.stamps[i], stored_from_new * joining.trajectory.poses[i]);
  std::stable_sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  slam::Trajectory both;
  for (const auto& [t, pose] : all) both.push_back(t, pose);
  slam::write_tum(out / "trajectory.tum", both);
}

}  // namespace

std::string folder_name(const std::filesystem::path& dir) {
  const std::filesystem::path p = dir.lexically_normal();
  return p.has_filename() ? p.filename().string() : p.parent_path().filename().string();
}

JoinFilesReport join_session_folders(const std::filesystem::path& session, const std::filesystem::path& stored,
                                     const JoinFilesOptions& options) {
  const SessionFiles stored_files = read_session(stored);
  const SessionFiles joining = read_session(session);
  const slam::PriorMap prior = slam::prepare_prior_map(xyz(stored_files.map, Eigen::Isometry3d::Identity()));
  if (const std::string problem = slam::check_prior_map(prior); !problem.empty())
    throw InputError((stored / "map.ply").string(), "", "cannot be joined to: " + problem);
  const slam::VoxelHashMap index = slam::index_prior_map(prior);
  slam::Trajectory search_trajectory = joining.trajectory;
  for (Eigen::Isometry3d& pose : search_trajectory.poses) pose = options.shift * pose;
  slam::SessionJoinConfig config = options.config;
  config.cancel = options.cancel;
  JoinFilesReport report;
  report.result = slam::join_session(prior, index, xyz(joining.map, options.shift), search_trajectory, config);
  report.result.stored_from_new = report.result.stored_from_new * options.shift;
  report.stored_name = folder_name(stored);
  const slam::SessionJoinResult& r = report.result;
  nlohmann::json j = {{"joined_to", report.stored_name}, {"success", r.success}, {"failure", r.failure},
                      {"places_tried", r.places_tried}, {"places_localised", r.places_localised},
                      {"places_agreeing", r.places_agreeing}, {"overlap", r.overlap}};
  if (r.success) {
    j["stored_from_new"] = pose_json(r.stored_from_new);
    j["first_agreeing_path_m"] = r.first_agreeing_path_m;
  }
  nlohmann::json places = nlohmann::json::array();
  for (const slam::JoinPlace& p : r.places)
    places.push_back({{"path_m", p.path_m}, {"localised", p.result.success}, {"agrees", p.agrees},
                      {"overlap", p.result.overlap}, {"failure", p.result.failure}});
  j["places"] = std::move(places);
  report.json = j.dump(2);
  if (r.success) {
    // Written whole or not at all: a temporary file renamed over it.
    const std::filesystem::path file = session / kJoinedFile, part = session / "joined.json.partial";
    {
      std::ofstream out(part);
      out << report.json << '\n';
      if (!out) throw InputError(part.string(), "", "cannot be written");
    }
    std::filesystem::rename(part, file);
    if (!options.out.empty()) write_joined(options.out, stored_files, joining, r.stored_from_new);
  }
  return report;
}

std::vector<JoinFilesReport> join_previous_session(const std::filesystem::path& session, int tries,
                                                   const JoinFilesOptions& options) {
  const std::filesystem::path dir = session.lexically_normal();
  const std::string name = folder_name(dir);
  const std::filesystem::path root = dir.has_filename() ? dir.parent_path() : dir.parent_path().parent_path();
  std::vector<std::string> earlier;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(root, ec)) {
    const std::string other = entry.path().filename().string();
    if (other < name && entry.is_directory(ec) && std::filesystem::exists(entry.path() / "map.ply", ec) &&
        std::filesystem::exists(entry.path() / "trajectory.tum", ec))
      earlier.push_back(other);
  }
  std::sort(earlier.rbegin(), earlier.rend());
  std::vector<JoinFilesReport> reports;
  for (const std::string& other : earlier) {
    if (static_cast<int>(reports.size()) >= tries || (options.cancel != nullptr && options.cancel->load())) break;
    try {
      reports.push_back(join_session_folders(session, root / other, options));
    } catch (const std::exception& e) {
      JoinFilesReport failed;
      failed.stored_name = other;
      failed.result.failure = e.what();
      reports.push_back(std::move(failed));
    }
    if (reports.back().result.success) break;
  }
  return reports;
}

}  // namespace adit::products
