#include "console_server.hpp"

#include <httplib.h>

#include <chrono>
#include <fstream>
#include <memory>
#include <random>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/common/log.hpp"
#include "adit/protocol/localise_hint.hpp"
#include "adit/protocol/session_state.hpp"
#include "console_downloads.hpp"
#include "console_events.hpp"
#include "console_feed.hpp"
#include "console_grid.hpp"
#include "console_sessions.hpp"

namespace adit::tools::console {
namespace {

using namespace std::chrono_literals;

// The one way the console talks to the payload's command channel: the
// client's own send path (request id, resend every 250 ms, ack), so whatever
// `adit start` does to a command (signing) the console's commands get too.
std::optional<command_ack_t> payload_command(const ClientOptions& client, const std::string& verb,
                                             const std::vector<std::string>& args) {
  LcmClient lcm(client);
  return lcm.command(verb, args);
}

// The protocol's name of a status_t/command_ack_t state.
std::string state_name(int state) {
  return std::string(protocol::state_name(static_cast<protocol::SessionState>(state)));
}

void reply_json(httplib::Response& res, int status, const nlohmann::json& body) {
  res.status = status;
  res.set_header("Cache-Control", "no-store");
  res.set_content(body.dump(), "application/json");
}

void reply_error(httplib::Response& res, int status, const std::string& message) {
  reply_json(res, status, {{"error", message}});
}

// A grid or block PNG and where it lies (docs/CONSOLE.md).
void reply_grid(httplib::Response& res, const GridBytes& grid) {
  res.set_header("X-Grid-Session", grid.session);
  res.set_header("X-Grid-Version", std::to_string(grid.version));
  res.set_header("X-Grid-Patches", std::to_string(grid.patches));
  res.set_header("X-Grid-Resolution", fmt::format("{}", grid.resolution_m));
  res.set_header("X-Grid-Origin-X", fmt::format("{}", grid.origin_x));
  res.set_header("X-Grid-Origin-Y", fmt::format("{}", grid.origin_y));
  res.set_header("X-Grid-Width", std::to_string(grid.width));
  res.set_header("X-Grid-Height", std::to_string(grid.height));
  res.set_header("Cache-Control", "no-store");
  res.set_content(grid.png, "image/png");
}

std::optional<nlohmann::json> body_json(const httplib::Request& req, httplib::Response& res) {
  try {
    auto j = nlohmann::json::parse(req.body);
    if (j.is_object()) return j;
  } catch (const nlohmann::json::exception&) {
  }
  reply_error(res, 400, "the request body is not a JSON object");
  return std::nullopt;
}

// HINT's fields from the request, as the command's key=value arguments: a
// number as written, anything else as text for parse_localise_hint to refuse.
std::vector<std::string> hint_args_of(const nlohmann::json& j) {
  std::vector<std::string> args;
  for (const char* key : {"x", "y", "radius", "heading", "heading_tolerance"}) {
    const auto it = j.find(key);
    if (it == j.end() || it->is_null()) continue;
    args.push_back(std::string(key) + "=" + (it->is_string() ? it->get<std::string>() : it->dump()));
  }
  return args;
}

std::string string_field(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}

// A file with Range support (httplib answers 206 for a byte range of a sized
// provider), read in pieces so a large map never sits in memory.
void reply_file(httplib::Response& res, const std::filesystem::path& file, const std::string& type) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  auto in = std::make_shared<std::ifstream>(file, std::ios::binary);
  if (ec || !*in) {
    reply_error(res, 404, "no such file");
    return;
  }
  // A validator, so a browser resumes (If-Range) only a file that did not change.
  const auto mtime = std::filesystem::last_write_time(file, ec).time_since_epoch().count();
  res.set_header("ETag", fmt::format("\"{:x}-{:x}\"", size, mtime));
  res.set_header("Accept-Ranges", "bytes");
  res.set_header("Content-Disposition", fmt::format("attachment; filename=\"{}\"", file.filename().string()));
  res.set_content_provider(static_cast<std::size_t>(size), type,
                           [in](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
                             std::array<char, 64 * 1024> buffer{};
                             in->clear();
                             in->seekg(static_cast<std::streamoff>(offset));
                             while (length > 0) {
                               const std::size_t n = std::min(length, buffer.size());
                               in->read(buffer.data(), static_cast<std::streamsize>(n));
                               const auto got = static_cast<std::size_t>(in->gcount());
                               if (got == 0 || !sink.write(buffer.data(), got)) return false;
                               offset += got;
                               length -= got;
                             }
                             return true;
                           });
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    const std::string line = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (!line.empty()) out.push_back(line);
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return out;
}

}  // namespace

int serve_console(const ConsoleOptions& options, const std::atomic<bool>& stop) {
  EventHub hub;
  // The current session's map is kept on disk beside the downloaded ones: a
  // long session's map would otherwise grow the console's memory with it.
  std::filesystem::create_directories(options.data_dir);
  LiveFeed feed(options.client, hub, options.data_dir);
  MapDownloads downloads(options.client, options.data_dir / "maps", hub);
  ScanNames names(options.data_dir / "names.json");
  ControlGate gate(options.passphrase);
  // This process's event ids: a browser's Last-Event-ID from an earlier console is not resumed.
  const std::string instance = fmt::format("{:x}", std::random_device{}());

  httplib::Server server;
  // Each event stream holds a worker while the browser watches, and a browser
  // keeps up to 6 connections: 8 workers (httplib's default on 2 cores) would
  // starve with two browsers. httplib takes an owning raw pointer here.
  server.new_task_queue = [] { return new httplib::ThreadPool(32); };
  server.set_tcp_nodelay(true);  // a pose is a small write: no Nagle delay (latency target)
  server.set_keep_alive_timeout(5);

  if (!server.set_mount_point("/", options.web_dir.string())) {
    log::error("adit console: the web app folder {} does not exist (--web-dir)", options.web_dir.string());
    return 2;
  }
  if (!server.set_mount_point("/vendor/three", options.three_dir.string())) {
    log::error("adit console: three.js folder {} does not exist (--three-dir; Debian package libjs-three)",
               options.three_dir.string());
    return 2;
  }

  server.Get("/api/config", [&](const httplib::Request&, httplib::Response& res) {
    reply_json(res, 200, {{"payload", options.client.payload_id}, {"locked", gate.locked()},
                          {"trajectories", !options.sessions_dir.empty()}});
  });
  server.Get("/api/state", [&](const httplib::Request&, httplib::Response& res) {
    reply_json(res, 200, feed.snapshot());
  });

  server.Get("/api/events", [&](const httplib::Request& req, httplib::Response& res) {
    // Resume after the browser's Last-Event-ID when the hub still holds what
    // followed it; otherwise start with a snapshot (`hello`).
    std::uint64_t after = 0;
    bool resume = false;
    if (const auto last = resume_after(req.get_header_value("Last-Event-ID"), instance); last && *last <= hub.last_id()) {
      after = *last;
      resume = true;
    }
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Accel-Buffering", "no");
    auto state = std::make_shared<std::pair<std::uint64_t, bool>>(after, !resume);  // (after, send hello)
    res.set_chunked_content_provider("text/event-stream", [&, state](std::size_t, httplib::DataSink& sink) {
      if (stop || hub.closed()) {
        sink.done();
        return false;
      }
      const auto hello = [&] {
        state->first = hub.last_id();
        const Event e{state->first, "hello", feed.snapshot().dump()};
        const std::string frame = "retry: 1000\n" + sse_frame(e, instance);
        return sink.write(frame.data(), frame.size());
      };
      if (state->second) {
        state->second = false;
        return hello();
      }
      const auto batch = hub.wait_after(state->first, 10s);
      if (batch.lost) return hello();
      if (batch.events.empty()) {
        static constexpr char kKeepAlive[] = ": keep-alive\n\n";
        return sink.write(kKeepAlive, sizeof kKeepAlive - 1);
      }
      std::string frames;
      for (const Event& e : batch.events) frames += sse_frame(e, instance);
      state->first = batch.events.back().id;
      return sink.write(frames.data(), frames.size());
    });
  });

  server.Get(R"(/api/tile/(-?\d+))", [&](const httplib::Request& req, httplib::Response& res) {
    std::int64_t id = 0;
    std::int32_t have = 0;
    int every = 1;
    try {
      id = std::stoll(req.matches[1]);
      if (req.has_param("have")) have = std::stoi(req.get_param_value("have"));
      if (req.has_param("every")) every = std::stoi(req.get_param_value("every"));
    } catch (const std::exception&) {
      reply_error(res, 400, "tile id, have and every are integers");
      return;
    }
    if (every < 1 || every > 1000) {
      reply_error(res, 400, "every must be 1..1000");
      return;
    }
    const auto tile = feed.tile(id, have, every);
    if (!tile) {
      reply_error(res, 404, fmt::format("tile {} is not held", id));
      return;
    }
    res.set_header("X-Tile-Version", std::to_string(tile->version));
    res.set_header("X-Tile-From", std::to_string(tile->from));
    res.set_header("X-Tile-Segments", std::to_string(tile->n_segments));
    res.set_header("X-Tile-Points", std::to_string(tile->n_points));
    res.set_header("Cache-Control", "no-store");
    res.set_content(tile->body, "application/octet-stream");
  });

  // The live 2D grid as one PNG (console_grid.hpp) and where it lies, for a
  // person or a tool; the page fetches it in blocks (below).
  server.Get("/api/grid", [&](const httplib::Request&, httplib::Response& res) {
    std::shared_ptr<const GridBytes> grid;
    try {
      grid = feed.grid();
    } catch (const std::runtime_error& e) {
      reply_error(res, 500, e.what());
      return;
    }
    if (!grid) {  // an answer, not an error: a browser logs every 404 as one
      res.status = 204;
      res.set_header("X-Grid-Problem", "no grid held: the payload has sent no grid patch for this session");
      return;
    }
    reply_grid(res, *grid);
  });

  // The grid's blocks and their versions: the page fetches this when a `grid`
  // event or the snapshot names a version it does not hold, then the blocks
  // whose versions moved.
  server.Get("/api/grid/blocks", [&](const httplib::Request&, httplib::Response& res) {
    const std::optional<nlohmann::json> blocks = feed.grid_blocks();
    if (!blocks) {
      res.status = 204;
      res.set_header("X-Grid-Problem", "no grid held: the payload has sent no grid patch for this session");
      return;
    }
    reply_json(res, 200, *blocks);
  });

  server.Get(R"(/api/grid/block/(-?\d+)/(-?\d+))", [&](const httplib::Request& req, httplib::Response& res) {
    std::int32_t x = 0, y = 0;
    try {
      x = std::stoi(req.matches[1]);
      y = std::stoi(req.matches[2]);
    } catch (const std::exception&) {
      reply_error(res, 400, "a block's x and y are 32-bit integers");
      return;
    }
    std::shared_ptr<const GridBytes> block;
    try {
      block = feed.grid_block(x, y);
    } catch (const std::runtime_error& e) {
      reply_error(res, 500, e.what());
      return;
    }
    if (!block) {  // a new session can empty a block the page was told of: not an error
      res.status = 204;
      res.set_header("X-Grid-Problem", fmt::format("no grid block ({}, {}) held", x, y));
      return;
    }
    reply_grid(res, *block);
  });

  server.Post("/api/unlock", [&](const httplib::Request& req, httplib::Response& res) {
    const auto body = body_json(req, res);
    if (!body) return;
    if (const auto token = gate.unlock(string_field(*body, "passphrase"))) {
      reply_json(res, 200, {{"token", *token}});
      return;
    }
    std::this_thread::sleep_for(1s);  // slows guessing
    reply_error(res, 403, "wrong passphrase");
  });

  server.Post("/api/command", [&](const httplib::Request& req, httplib::Response& res) {
    const auto body = body_json(req, res);
    if (!body) return;
    if (!gate.allows(req.get_header_value("X-Adit-Token"))) {
      reply_error(res, 403, "control is locked: enter the operator passphrase");
      return;
    }
    const std::string verb = string_field(*body, "verb");
    if (verb != "START" && verb != "STOP" && verb != "HINT") {
      reply_error(res, 400, fmt::format("verb '{}' is not START, STOP or HINT", verb));
      return;
    }
    const std::string name = string_field(*body, "name");
    std::vector<std::string> args;
    if (verb == "START" && !name.empty()) {
      if (const std::string problem = scan_name_problem(name); !problem.empty()) {
        reply_error(res, 400, problem);
        return;
      }
      args.push_back("name=" + name);
    }
    if (verb == "HINT") {
      // The protocol's own parser checks the fields (names, numbers, ranges).
      std::string error;
      const auto hint = protocol::parse_localise_hint(hint_args_of(*body), error);
      if (!hint) {
        reply_error(res, 400, error);
        return;
      }
      args = protocol::localise_hint_args(*hint);
    }
    const auto ack = payload_command(options.client, verb, args);
    if (!ack) {
      reply_error(res, 504, fmt::format("payload '{}' did not answer {} within {} s", options.client.payload_id,
                                        verb, options.client.timeout_s));
      return;
    }
    if (ack->accepted && verb == "START" && !name.empty() && !ack->session_id.empty()) names.set(ack->session_id, name);
    const nlohmann::json answer = {{"verb", verb},         {"accepted", ack->accepted}, {"reason", ack->reason},
                                   {"state", state_name(ack->state)}, {"session", ack->session_id}};
    hub.publish("command", answer.dump());
    reply_json(res, ack->accepted ? 200 : 409, answer);
  });

  server.Get("/api/sessions", [&](const httplib::Request&, httplib::Response& res) {
    const auto ack = payload_command(options.client, "SESSIONS", {});
    if (!ack) {
      reply_error(res, 504, fmt::format("payload '{}' did not answer within {} s", options.client.payload_id,
                                        options.client.timeout_s));
      return;
    }
    if (!ack->accepted) {
      reply_error(res, 502, ack->reason);
      return;
    }
    reply_json(res, 200, {{"sessions", describe_sessions(lines_of(ack->detail), names, options.sessions_dir)},
                          {"downloads", downloads.list()}});
  });

  server.Post("/api/downloads", [&](const httplib::Request& req, httplib::Response& res) {
    const auto body = body_json(req, res);
    if (!body) return;
    const std::string session = string_field(*body, "session");
    const std::string format = string_field(*body, "format");
    if (!plain_session_id(session)) {
      reply_error(res, 400, fmt::format("'{}' is not a session id", session));
      return;
    }
    if (format != "ply" && format != "las" && format != "pcd") {
      reply_error(res, 400, fmt::format("format '{}' is not ply, las or pcd", format));
      return;
    }
    reply_json(res, 202, downloads.request(session, format));
  });
  server.Get("/api/downloads", [&](const httplib::Request&, httplib::Response& res) {
    reply_json(res, 200, downloads.list());
  });

  server.Get(R"(/files/([A-Za-z0-9_-]{1,64})/([a-z_0-9]+\.[a-z]+))", [&](const httplib::Request& req,
                                                                      httplib::Response& res) {
    const std::string session = req.matches[1];
    const std::string name = req.matches[2];
    if (name == "map.ply" || name == "map.las" || name == "map.pcd") {
      const auto file = downloads.file(session, name.substr(4));
      if (file.empty()) {
        reply_error(res, 404, fmt::format("{} of {} is not downloaded yet (POST /api/downloads)", name, session));
        return;
      }
      reply_file(res, file, "application/octet-stream");
      return;
    }
    if (const std::optional<SessionFile> file = session_file(name)) {
      if (options.sessions_dir.empty()) {
        reply_error(res, 404, "this console does not run on the payload (no --sessions-dir): only maps");
        return;
      }
      const std::filesystem::path on_disk = options.sessions_dir / session / file->path;
      if (*file->path.begin() == "products" && !std::filesystem::exists(on_disk)) {
        reply_error(res, 404, fmt::format("{} of {} is not made (yet): the payload makes a session's pictures "
                                          "after it stops (session.products)", name, session));
        return;
      }
      reply_file(res, on_disk, file->type);
      return;
    }
    reply_error(res, 404, fmt::format("no file '{}'", name));
  });

  if (!server.bind_to_port(options.host, options.port)) {
    log::error("adit console: cannot listen on {}:{}", options.host, options.port);
    return 2;
  }
  log::info("adit console: http://{}:{}/ (payload '{}', control {})", options.host, options.port,
            options.client.payload_id, gate.locked() ? "locked by a passphrase" : "open to any browser");
  std::atomic<bool> ended{false};  // the server returned by itself (a socket error)
  std::thread stopper([&] {
    while (!stop && !ended) std::this_thread::sleep_for(100ms);
    hub.close();
    server.stop();
  });
  const bool clean = server.listen_after_bind();
  ended = true;
  stopper.join();
  return clean || stop ? 0 : 1;
}

}  // namespace adit::tools::console
