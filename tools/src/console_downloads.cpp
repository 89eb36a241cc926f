#include "console_downloads.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>

#include <fmt/format.h>

#include "adit/protocol/map_export.hpp"
#include "adit/protocol/tile_assembler.hpp"

namespace adit::tools::console {

bool plain_session_id(const std::string& id) {
  return !id.empty() && id.size() <= 64 && std::all_of(id.begin(), id.end(), [](char c) {
           return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '_';
         });
}

MapDownloads::MapDownloads(ClientOptions options, std::filesystem::path folder, EventHub& hub)
    : options_(std::move(options)), folder_(std::move(folder)), hub_(hub) {}

MapDownloads::~MapDownloads() {
  std::vector<std::thread*> running;
  {
    const std::lock_guard lock(mutex_);
    for (auto& [key, job] : jobs_) running.push_back(&job->thread);
  }
  for (std::thread* t : running)
    if (t->joinable()) t->join();
}

nlohmann::json MapDownloads::describe(const Job& job) {
  return {{"session", job.session}, {"format", job.format}, {"state", job.state}, {"error", job.error},
          {"have", job.have},       {"wanted", job.wanted}, {"points", job.points}, {"bytes", job.bytes},
          {"url", job.state == "done" ? fmt::format("/files/{}/map.{}", job.session, job.format) : ""}};
}

nlohmann::json MapDownloads::request(const std::string& session, const std::string& format) {
  const std::string key = session + "." + format;
  std::unique_ptr<Job> failed;  // a failed one, tried again: joined outside the lock (it publishes under it)
  nlohmann::json state;
  {
    const std::lock_guard lock(mutex_);
    auto& slot = jobs_[key];
    if (slot && slot->state != "failed") return describe(*slot);
    failed = std::move(slot);
    slot = std::make_unique<Job>();
    slot->session = session;
    slot->format = format;
    Job& job = *slot;
    job.thread = std::thread([this, &job] { run(job); });
    state = describe(job);
  }
  if (failed && failed->thread.joinable()) failed->thread.join();
  return state;
}

nlohmann::json MapDownloads::list() const {
  const std::lock_guard lock(mutex_);
  nlohmann::json out = nlohmann::json::array();
  for (const auto& [key, job] : jobs_) out.push_back(describe(*job));
  return out;
}

std::filesystem::path MapDownloads::file(const std::string& session, const std::string& format) const {
  const std::lock_guard lock(mutex_);
  const auto it = jobs_.find(session + "." + format);
  if (it == jobs_.end() || it->second->state != "done") return {};
  return folder_ / session / ("map." + format);
}

void MapDownloads::run(Job& job) {
  const auto publish = [&] {
    nlohmann::json j;
    {
      const std::lock_guard lock(mutex_);
      j = describe(job);
    }
    hub_.publish("download", j.dump());
  };
  publish();
  try {
    LcmClient client(options_);
    protocol::TileAssembler tiles;
    auto last = std::chrono::steady_clock::now();
    const auto result = client.download(job.session, tiles, [&](std::size_t have, std::size_t wanted) {
      {
        const std::lock_guard lock(mutex_);
        job.have = have;
        job.wanted = wanted;
      }
      if (std::chrono::steady_clock::now() - last > std::chrono::milliseconds(200)) {
        last = std::chrono::steady_clock::now();
        publish();
      }
    });
    if (!result.ok) throw std::runtime_error(result.error);
    auto points = tiles.points();
    place_downloaded_points(points, result.frame);  // as `adit download` writes it
    const std::filesystem::path dir = folder_ / job.session;
    std::filesystem::create_directories(dir);
    const std::filesystem::path final_file = dir / ("map." + job.format);
    const std::filesystem::path part = dir / ("map." + job.format + ".part");
    protocol::write_map(part, *protocol::parse_map_format(job.format), points);
    std::filesystem::rename(part, final_file);
    const std::lock_guard lock(mutex_);
    job.points = points.size();
    job.bytes = std::filesystem::file_size(final_file);
    job.have = job.wanted;
    job.state = "done";
  } catch (const std::exception& e) {
    const std::lock_guard lock(mutex_);
    job.state = "failed";
    job.error = e.what();
  }
  publish();
}

}  // namespace adit::tools::console
