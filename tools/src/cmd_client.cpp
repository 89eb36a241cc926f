// adit status | watch | start | stop | hint | export | grid | sessions | ping: talk to a running aditd
// over LCM (docs/PROTOCOL.md).

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/products/grid_io.hpp"
#include "adit/protocol/grid_mosaic.hpp"
#include "adit/protocol/localise_hint.hpp"
#include "adit/protocol/session_state.hpp"
#include "client_options.hpp"
#include "commands.hpp"

namespace adit::tools {
namespace {

std::string state_text(std::int8_t state) {
  if (state < 0 || state > 2) return fmt::format("state {}", state);
  return std::string(protocol::state_name(static_cast<protocol::SessionState>(state)));
}

int no_answer(const ClientOptions& o) {
  fmt::print(stderr, "adit: error: no payload '{}' answered within {} s on {}\n", o.payload_id, o.timeout_s,
             o.lcm_url);
  return kExitFailure;
}

// Sends one command and prints its ack; exit 0 only when accepted.
int run_command(const ClientOptions& options, const std::string& verb, bool print_detail,
                const std::vector<std::string>& args = {}) {
  LcmClient client(options);
  const auto ack = client.command(verb, args);
  if (!ack) return no_answer(options);
  if (!ack->accepted) {
    fmt::print(stderr, "adit: {} rejected: {} (state {})\n", verb, ack->reason, state_text(ack->state));
    return kExitFailure;
  }
  if (print_detail) {
    fmt::print("{}", ack->detail);
  } else {
    fmt::print("{}: {} (state {}{}; answered in {:.0f} ms)\n", verb, ack->reason, state_text(ack->state),
               ack->session_id.empty() ? "" : ", session " + ack->session_id, client.last_round_trip_ms());
  }
  return kExitOk;
}

std::string pose_flags(std::int32_t flags) {
  std::string out = (flags & pose_t::FLAG_VALID) ? "valid" : "INVALID";
  if (flags & pose_t::FLAG_DEGENERATE) out += ",degenerate";
  if (flags & pose_t::FLAG_HELD) out += ",held";
  if (flags & pose_t::FLAG_LOST) out += ",LOST";
  if (flags & pose_t::FLAG_RELOCALISED) out += ",relocalised";
  return out;
}

// The status on one line; with the session's loop closure (`loops`, its
// latest loop_status_t, or null) before any fault.
std::string status_line(const status_t& s, const loop_status_t* loops) {
  std::string line = fmt::format("{} {}", state_text(s.state), s.session_id.empty() ? "-" : s.session_id);
  for (const auto& h : s.sensors) line += fmt::format(" | {} {:.1f} Hz drop {}", h.name, h.packet_rate_hz, h.packets_dropped);
  line += fmt::format(" | map {} pts {} tiles | disk {:.1f} GB", s.map_points, s.map_tiles, s.disk_free_bytes / 1e9);
  if (loops != nullptr && loops->session_id == s.session_id)
    line += fmt::format(" | loops {} closed, {} refused, correction {:.2f} m", loops->accepted, loops->rejected,
                        loops->correction_m);
  if (!s.fault.empty()) line += " | FAULT " + s.fault;
  return line;
}

void register_status(CLI::App& app, int& status) {
  auto options = std::make_shared<ClientOptions>();
  CLI::App* sub = app.add_subcommand("status", "Print the payload's state and health once");
  add_client_options(*sub, *options);
  sub->callback([options, &status] {
    LcmClient client(*options);
    // The status, with the session's loop closure when it runs: loop_status_t
    // comes just before each status while mapping, so the wait goes on to a
    // second status when the first came without one (0.5 s at most).
    std::optional<status_t> s;
    std::optional<loop_status_t> loops;
    int statuses = 0;
    LcmClient::FollowHandlers handlers;
    handlers.loop_status = [&](const loop_status_t& l) { loops = l; };
    handlers.status = [&](const status_t& m) {
      s = m;
      ++statuses;
    };
    const auto start = std::chrono::steady_clock::now();
    client.follow(handlers, [&] {
      const bool whole = s && (loops || statuses >= 2 || s->state != status_t::STATE_MAPPING);
      return whole || std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >
                          options->timeout_s;
    });
    if (!s) {
      status = no_answer(*options);
      return;
    }
    fmt::print("payload   {}\nstate     {}\nsession   {}\nmap       {} points in {} tiles\ndisk free {:.1f} GB\n",
               s->payload_id, state_text(s->state), s->session_id.empty() ? "-" : s->session_id, s->map_points,
               s->map_tiles, s->disk_free_bytes / 1e9);
    for (const auto& h : s->sensors)
      fmt::print("sensor    {}: {:.1f} Hz, {} dropped, time offset {:.3f} s\n", h.name, h.packet_rate_hz,
                 h.packets_dropped, h.time_offset_s);
    for (const auto& t : s->threads)
      fmt::print("thread    {}: load {:.0f}%, queue {}/{}\n", t.name, 100 * t.load, t.queue_depth, t.queue_capacity);
    if (loops && loops->session_id == s->session_id)
      fmt::print("loops     {} closed, {} refused ({} candidates, {} keyframes); correction {:.2f} m {:.1f} deg\n",
                 loops->accepted, loops->rejected, loops->candidates, loops->keyframes, loops->correction_m,
                 loops->correction_deg);
    else if (s->state == status_t::STATE_MAPPING)
      fmt::print("loops     off\n");
    fmt::print("fault     {}\n", s->fault.empty() ? "none" : s->fault);
    status = kExitOk;
  });
}

void register_watch(CLI::App& app, int& status) {
  auto options = std::make_shared<ClientOptions>();
  auto duration = std::make_shared<double>(0.0);
  CLI::App* sub = app.add_subcommand("watch", "Show pose, rates and health on one live line");
  add_client_options(*sub, *options);
  sub->add_option("--duration", *duration, "Stop after this many seconds (0: until interrupted)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  sub->callback([options, duration, &status] {
    using Clock = std::chrono::steady_clock;
    LcmClient client(*options);
    const auto start = Clock::now();
    auto last_message = start;
    auto last_print = start;
    std::size_t poses = 0;
    double pose_rate = 0;
    auto rate_window = start;
    std::size_t rate_count = 0;
    pose_t pose{};  // value-initialised: LCM types leave numbers unset
    frame_t frame{};  // map <- odometry; none yet (a zero quaternion): identity, the odometry frame
    std::string health = "(no status yet)";
    bool any = false;
    const auto print = [&] {
      const Eigen::Vector3d p =
          map_from_odometry(frame) * Eigen::Vector3d(pose.position[0], pose.position[1], pose.position[2]);
      fmt::print("\r\033[K#{} x {:.2f} y {:.2f} z {:.2f}{} {} {:.1f} Hz | {}", pose.seq, p.x(), p.y(), p.z(),
                 frame.source == frame_t::SOURCE_PRIOR_MAP ? " (prior map)" : "", pose_flags(pose.flags), pose_rate,
                 health);
      std::fflush(stdout);
      last_print = Clock::now();
    };
    const auto elapsed = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
    bool silent = false;
    LcmClient::FollowHandlers handlers;
    handlers.frame = [&](const frame_t& f) {
      if (f.session_id == pose.session_id || pose.session_id.empty()) frame = f;
    };
    handlers.pose = [&](const pose_t& p) {
      pose = p;
      ++poses;
      ++rate_count;
      any = true;
      last_message = Clock::now();
      if (elapsed(rate_window) >= 1.0) {
        pose_rate = rate_count / elapsed(rate_window);
        rate_count = 0;
        rate_window = Clock::now();
      }
      if (elapsed(last_print) >= 0.1) print();
    };
    std::optional<loop_status_t> loops;  // the newest; the daemon sends it just before its status
    handlers.loop_status = [&](const loop_status_t& l) {
      if (l.payload_id == options->payload_id) loops = l;
    };
    handlers.status = [&](const status_t& s) {
      health = status_line(s, loops ? &*loops : nullptr);
      any = true;
      last_message = Clock::now();
      print();
    };
    client.follow(handlers, [&] {
      if (elapsed(last_message) > options->timeout_s) silent = true;
      return silent || (*duration > 0 && elapsed(start) >= *duration);
    });
    if (any) fmt::print("\n{} poses received\n", poses);
    status = silent && !any ? no_answer(*options) : kExitOk;
    if (silent && any) {
      fmt::print(stderr, "adit: error: payload '{}' went silent for {} s\n", options->payload_id, options->timeout_s);
      status = kExitFailure;
    }
  });
}

void register_verb(CLI::App& app, int& status, const std::string& name, const std::string& verb,
                   const std::string& help, bool print_detail) {
  auto options = std::make_shared<ClientOptions>();
  CLI::App* sub = app.add_subcommand(name, help);
  add_client_options(*sub, *options);
  sub->callback([options, &status, verb, print_detail] { status = run_command(*options, verb, print_detail); });
}

void register_export(CLI::App& app, int& status) {
  auto options = std::make_shared<ClientOptions>();
  auto session = std::make_shared<std::string>();
  CLI::App* sub = app.add_subcommand("export", "Print where a stored session's map files are on the payload");
  add_client_options(*sub, *options);
  sub->add_option("--session", *session, "Session id (default: the current or last session)");
  sub->callback([options, session, &status] {
    status = run_command(*options, "EXPORT", true, session->empty() ? std::vector<std::string>{} : std::vector{*session});
  });
}

// HINT: where the payload is in the prior map's frame, for its search against
// the prior (docs/PRIOR-MAP.md).
void register_hint(CLI::App& app, int& status) {
  auto options = std::make_shared<ClientOptions>();
  auto hint = std::make_shared<protocol::LocaliseHint>();
  auto heading = std::make_shared<double>(std::nan(""));
  CLI::App* sub = app.add_subcommand("hint", "Tell the mapping payload roughly where it is in its prior map");
  add_client_options(*sub, *options);
  sub->add_option("--x", hint->x_m, "Position in the prior map's frame, m")->required();
  sub->add_option("--y", hint->y_m, "Position in the prior map's frame, m")->required();
  sub->add_option("--radius", hint->radius_m, "How far off the position may be, m")->capture_default_str()->check(CLI::Range(0.5, 100.0));
  sub->add_option("--heading", *heading, "The way the payload faces, degrees counter-clockwise from the prior's x axis (default: any)");
  sub->add_option("--heading-tolerance", hint->heading_tolerance_deg, "Degrees either side of --heading")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 180.0));
  sub->callback([options, hint, heading, &status] {
    if (!std::isnan(*heading)) hint->heading_deg = *heading;
    status = run_command(*options, "HINT", false, protocol::localise_hint_args(*hint));
  });
}

// The live 2D grid as the tablet receives it (grid_patch_t on GRID), written
// as a ROS map_server PGM + YAML. The daemon sends every patch again within
// grid.refresh_s, so listening that long gets the whole grid.
void register_grid(CLI::App& app, int& status) {
  auto options = std::make_shared<ClientOptions>();
  auto out = std::make_shared<std::string>();
  auto duration = std::make_shared<double>(12.0);
  CLI::App* sub = app.add_subcommand("grid", "Receive the live 2D occupancy grid and write it as PGM + YAML");
  add_client_options(*sub, *options);
  sub->add_option("--out", *out, "Files STEM.pgm and STEM.yaml (ROS map_server)")->required();
  sub->add_option("--duration", *duration, "Listen this many seconds (the daemon's grid.refresh_s and more)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  sub->callback([options, out, duration, &status] {
    using Clock = std::chrono::steady_clock;
    LcmClient client(*options);
    protocol::GridMosaic mosaic;
    std::size_t messages = 0;
    std::string first_problem;
    const auto start = Clock::now();
    LcmClient::FollowHandlers handlers;
    handlers.grid_patch = [&](const grid_patch_t& p) {
      ++messages;
      if (std::string problem = mosaic.accept(p); !problem.empty() && first_problem.empty())
        first_problem = std::move(problem);
    };
    client.follow(handlers, [&] { return std::chrono::duration<double>(Clock::now() - start).count() >= *duration; });
    if (!first_problem.empty())
      fmt::print(stderr, "adit: {} grid messages refused; the first: {}\n", mosaic.counts().refused, first_problem);
    if (mosaic.patch_count() == 0) {
      fmt::print(stderr, "adit: error: no grid patch from payload '{}' within {} s on {}\n", options->payload_id,
                 *duration, options->lcm_url);
      status = kExitFailure;
      return;
    }
    const products::Grid2d grid = products::grid_of(mosaic.image());
    const std::uintmax_t bytes = products::write_grid(*out, grid);
    fmt::print("session {}: {} patches ({} messages), {} x {} cells at {} m: {} occupied, {} free; {}.pgm/.yaml, {} "
               "bytes\n",
               mosaic.session_id(), mosaic.patch_count(), messages, grid.width, grid.height, grid.resolution_m,
               grid.count(products::kOccupied), grid.count(products::kFree), *out, bytes);
    status = kExitOk;
  });
}

}  // namespace

void register_client_commands(CLI::App& app, int& status) {
  register_status(app, status);
  register_watch(app, status);
  register_hint(app, status);
  register_verb(app, status, "start", "START", "Start a mapping session", false);
  register_verb(app, status, "stop", "STOP", "Stop the mapping session (the payload flushes, then goes idle)", false);
  register_export(app, status);
  register_grid(app, status);
  register_verb(app, status, "sessions", "SESSIONS", "List the sessions stored on the payload", true);
  register_verb(app, status, "ping", "PING", "Check that the payload answers commands", false);
}

}  // namespace adit::tools
