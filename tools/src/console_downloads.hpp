#pragma once
// adit console: maps for the browser to download. The console fetches a
// session's map over LCM exactly as `adit download` does
// (LcmClient::download into a TileAssembler, protocol::write_map), in a
// thread per request, into its data folder; progress goes out as `download`
// events; the finished file is served over HTTP with Range (resume).

#include <filesystem>
#include <map>
#include <mutex>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "console_events.hpp"
#include "lcm_client.hpp"

namespace adit::tools::console {

// A session id as aditd names folders ([A-Za-z0-9_-], 1..64): nothing else
// reaches a path.
bool plain_session_id(const std::string& id);

class MapDownloads {
 public:
  MapDownloads(ClientOptions options, std::filesystem::path folder, EventHub& hub);
  ~MapDownloads();  // waits for running downloads (each ends within the client timeout)
  MapDownloads(const MapDownloads&) = delete;
  MapDownloads& operator=(const MapDownloads&) = delete;

  // Starts fetching `session`'s map as `format` (ply, las, pcd) unless it is
  // running or done already; returns the job's state.
  nlohmann::json request(const std::string& session, const std::string& format);
  nlohmann::json list() const;
  // The finished file of a session and format, when there is one.
  std::filesystem::path file(const std::string& session, const std::string& format) const;

 private:
  struct Job {
    std::string session, format, state = "running", error;  // running, done, failed
    std::size_t have = 0, wanted = 0, points = 0;
    std::uintmax_t bytes = 0;
    std::thread thread;
  };
  static nlohmann::json describe(const Job& job);
  void run(Job& job);

  ClientOptions options_;
  std::filesystem::path folder_;
  EventHub& hub_;
  mutable std::mutex mutex_;
  std::map<std::string, std::unique_ptr<Job>> jobs_;  // by "<session>.<format>"
};

}  // namespace adit::tools::console
