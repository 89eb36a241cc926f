#include "adit/eval/loop_summary_io.hpp"

#include <cmath>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/common/error.hpp"

namespace adit::eval {
namespace {

using nlohmann::json;

const json& member(const json& object, const char* key, const std::string& where, const std::string& path) {
  if (!object.is_object() || !object.contains(key))
    throw InputError(where, path.empty() ? key : path + "." + key, "missing");
  return object[key];
}

std::size_t index_of(const json& value, const std::string& where, const std::string& key) {
  if (!value.is_number_unsigned()) throw InputError(where, key, "expected a keyframe index (a whole number >= 0)");
  return value.get<std::size_t>();
}

std::vector<double> numbers_of(const json& value, std::size_t count, const std::string& where, const std::string& key) {
  if (!value.is_array() || value.size() != count)
    throw InputError(where, key, fmt::format("expected an array of {} numbers", count));
  std::vector<double> out;
  out.reserve(count);
  for (const json& v : value) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) throw InputError(where, key, "expected finite numbers");
    out.push_back(v.get<double>());
  }
  return out;
}

}  // namespace

std::vector<LoopEdgeRecord> read_loop_edges(std::istream& in, const std::filesystem::path& name) {
  const std::string where = name.string();
  json root;
  try {
    root = json::parse(in);
  } catch (const json::exception& e) {
    throw InputError(where, "", fmt::format("not JSON: {}", e.what()));
  }
  const json& loops = member(root, "loops", where, "");
  if (loops.is_object() && loops.contains("enabled") && loops["enabled"] == false)
    throw InputError(where, "loops.enabled", "loop closure was off in this session");
  const json& edges = member(loops, "edges", where, "loops");
  if (!edges.is_array())
    throw InputError(where, "loops.edges", "expected an array (written by aditd with loop closure)");
  std::vector<LoopEdgeRecord> out;
  out.reserve(edges.size());
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const std::string key = fmt::format("loops.edges[{}]", i);
    LoopEdgeRecord r;
    r.from = index_of(member(edges[i], "from", where, key), where, key + ".from");
    r.to = index_of(member(edges[i], "to", where, key), where, key + ".to");
    const std::vector<double> m = numbers_of(member(edges[i], "measurement", where, key), 7, where, key + ".measurement");
    Eigen::Quaterniond q(m[6], m[3], m[4], m[5]);
    if (!(q.norm() > 0.5 && q.norm() < 1.5)) throw InputError(where, key + ".measurement", "not a unit quaternion");
    q.normalize();
    r.measurement = slam::Pose::Identity();
    r.measurement.linear() = q.toRotationMatrix();
    r.measurement.translation() = Eigen::Vector3d(m[0], m[1], m[2]);
    const std::vector<double> info = numbers_of(member(edges[i], "information", where, key), 36, where, key + ".information");
    r.information = Eigen::Map<const slam::Matrix6d>(info.data());
    out.push_back(r);
  }
  return out;
}

std::vector<LoopEdgeRecord> read_loop_edges(const std::filesystem::path& summary_json) {
  std::ifstream in(summary_json);
  if (!in) throw InputError(summary_json.string(), "", "cannot open");
  return read_loop_edges(in, summary_json);
}

}  // namespace adit::eval
