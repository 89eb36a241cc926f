#pragma once
// adit console: the session list a browser shows. The ids come from the
// payload (the SESSIONS command); the names operators give scans are kept by
// the console (aditd has no field for them: START carries `name=` for a
// daemon that will); size, duration and figures come from the session's
// summary.json when the console runs on the payload and can read its folder.

#include <filesystem>
#include <mutex>
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
// `sessions_dir` is set (points, duration_s, bytes, files, poses, loops).
nlohmann::json describe_sessions(const std::vector<std::string>& ids, const ScanNames& names,
                                 const std::filesystem::path& sessions_dir);

}  // namespace adit::tools::console
