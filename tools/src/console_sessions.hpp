#pragma once
// adit console: the session list a browser shows. The ids come from the
// payload (the SESSIONS command); the names operators give scans are kept by
// the console (aditd has no field for them: START carries `name=` for a
// daemon that will); size, duration and figures come from the session's
// summary.json when the console runs on the payload and can read its folder.

#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace adit::tools::console {

class ScanNames {
 public:
  explicit ScanNames(std::filesystem::path file);  // a JSON object id -> name; created when first written
  void set(const std::string& session, const std::string& name);
  std::string get(const std::string& session) const;

 private:
  std::filesystem::path file_;
  mutable std::mutex mutex_;
  nlohmann::json names_ = nlohmann::json::object();
};

// An operator's scan name: 1..64 printable characters, or why not.
std::string scan_name_problem(const std::string& name);

// One entry per line of aditd's listing ("<id>" and its notes: "recovered",
// "joined to <id>"): id, name, notes, and what the session's folder tells when
// `sessions_dir` is set (points, duration_s, bytes, files, poses, loops, and
// whether its pictures are made: top_view, sections).
nlohmann::json describe_sessions(const std::vector<std::string>& ids, const ScanNames& names,
                                 const std::filesystem::path& sessions_dir);

// A file of a session's folder that a browser may fetch by `name` (GET
// /files/<session>/<name>): the trajectories and summary.json at its root, and
// what the payload made after the session (products/, docs/PRODUCTS.md): the
// top view (top_view.png), the cross-sections (sections.csv, section_NNN.svg).
// Its path within the folder and its media type; none for any other name.
struct SessionFile {
  std::filesystem::path path;
  std::string type;
};
std::optional<SessionFile> session_file(const std::string& name);

}  // namespace adit::tools::console
