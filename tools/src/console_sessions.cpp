#include "console_sessions.hpp"

#include <algorithm>
#include <fstream>
#include <string_view>

#include "adit/common/log.hpp"

namespace adit::tools::console {

ScanNames::ScanNames(std::filesystem::path file) : file_(std::move(file)) {
  std::ifstream in(file_);
  if (!in) return;
  try {
    names_ = nlohmann::json::parse(in);
    if (!names_.is_object()) throw std::runtime_error("not a JSON object");
  } catch (const std::exception& e) {
    log::warn("{}: scan names unreadable, starting afresh: {}", file_.string(), e.what());
    names_ = nlohmann::json::object();
  }
}

void ScanNames::set(const std::string& session, const std::string& name) {
  const std::lock_guard lock(mutex_);
  names_[session] = name;
  std::filesystem::create_directories(file_.parent_path());
  const std::filesystem::path part = file_.string() + ".part";
  std::ofstream(part) << names_.dump(2) << "\n";
  std::filesystem::rename(part, file_);
}

std::string ScanNames::get(const std::string& session) const {
  const std::lock_guard lock(mutex_);
  const auto it = names_.find(session);
  return it != names_.end() && it->is_string() ? it->get<std::string>() : std::string();
}

std::string scan_name_problem(const std::string& name) {
  if (name.empty()) return "the name is empty";
  if (name.size() > 64) return "the name is longer than 64 characters";
  for (const char c : name)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return "the name has a control character";
  return "";
}

nlohmann::json describe_sessions(const std::vector<std::string>& ids, const ScanNames& names,
                                 const std::filesystem::path& sessions_dir) {
  nlohmann::json out = nlohmann::json::array();
  for (const std::string& line : ids) {
    // aditd's listing: "<id>", then what it knows of it ("recovered", "joined to <id>").
    const std::size_t space = line.find(' ');
    const std::string id = line.substr(0, space);
    const std::string notes = space == std::string::npos ? std::string() : line.substr(space + 1);
    nlohmann::json entry = {{"id", id}, {"name", names.get(id)}};
    if (!notes.empty()) entry["notes"] = notes;
    if (!sessions_dir.empty()) {
      const std::filesystem::path dir = sessions_dir / id;
      std::error_code ec;
      std::uintmax_t bytes = 0;
      for (const auto& f : std::filesystem::recursive_directory_iterator(dir, ec))
        if (f.is_regular_file(ec)) bytes += f.file_size(ec);
      entry["bytes"] = bytes;
      entry["trajectory"] = std::filesystem::exists(dir / "trajectory.tum", ec);
      // Made by the payload after the session (products/, renamed into place when whole).
      entry["top_view"] = std::filesystem::exists(dir / session_file("top_view.png")->path, ec);
      std::size_t sections = 0;
      for (const auto& f : std::filesystem::directory_iterator(dir / "products" / "sections", ec))
        if (session_file(f.path().filename().string()) && f.path().extension() == ".svg") ++sections;
      entry["sections"] = sections;
      std::ifstream in(dir / "summary.json");
      if (in) {
        try {
          const auto s = nlohmann::json::parse(in);
          entry["points"] = s.at("map").at("points");
          entry["duration_s"] = s.at("timing").at("duration_s");
          entry["poses"] = s.at("poses").at("total");
          entry["invalid_poses"] = s.at("poses").at("invalid");
          if (s.contains("loops") && s["loops"].contains("accepted")) entry["loops"] = s["loops"]["accepted"];
        } catch (const std::exception& e) {
          entry["summary_error"] = e.what();
        }
      }
    }
    out.push_back(std::move(entry));
  }
  return out;
}

std::optional<SessionFile> session_file(const std::string& name) {
  if (name == "trajectory.tum" || name == "map_trajectory.tum") return SessionFile{name, "text/plain"};
  if (name == "summary.json") return SessionFile{name, "application/json"};
  if (name == "top_view.png") return SessionFile{std::filesystem::path("products") / name, "image/png"};
  if (name == "sections.csv") return SessionFile{std::filesystem::path("products") / "sections" / name, "text/csv"};
  // section_NNN.svg (cross_sections.hpp numbers them from 000).
  const std::string_view prefix = "section_", suffix = ".svg";
  if (name.size() > prefix.size() + suffix.size() && name.size() <= prefix.size() + suffix.size() + 6 &&
      name.starts_with(prefix) && name.ends_with(suffix)) {
    const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    if (std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
      return SessionFile{std::filesystem::path("products") / "sections" / name, "image/svg+xml"};
  }
  return std::nullopt;
}

}  // namespace adit::tools::console
