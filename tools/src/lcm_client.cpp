#include "lcm_client.hpp"

#include <cmath>
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <stdexcept>

#include <fmt/format.h>

#include "adit/common/clock.hpp"
#include "adit/command_t.hpp"
#include "adit/common/error.hpp"
#include "adit/protocol/channels.hpp"
#include "adit/protocol/command_auth.hpp"
#include "adit/protocol/checked_decode.hpp"
#include "adit/tile_segment_t.hpp"
#include "adit/tile_index_t.hpp"
#include "adit/tile_request_t.hpp"
#include "adit/file_chunk_t.hpp"
#include "adit/file_request_t.hpp"
#include "adit/protocol/product_files.hpp"

namespace adit::tools {
namespace {

using Clock = std::chrono::steady_clock;
using protocol::Channel;


double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Decodes one message body, or nullopt when it is not a `Message`.
template <typename Message>
std::optional<Message> decode(const lcm::ReceiveBuffer* rbuf) {
  Message m;
  if (!protocol::checked_decode(rbuf->data, rbuf->data_size, m)) return std::nullopt;
  return m;
}

constexpr std::size_t kMaxRequestEntries = 3000;  // tile_request_t stays < 60 KB
constexpr double kFrameWaitS = 0.6;              // a status period (0.5 s) and a little more

// A subscription for as long as it lives (LCM 1.3 takes no std::function).
class Listen {
 public:
  using Handler = std::function<void(const lcm::ReceiveBuffer*)>;
  Listen(lcm::LCM& lcm, const std::string& channel, Handler handler) : lcm_(lcm), handler_(std::move(handler)) {
    subscription_ = lcm_.subscribe(channel, &Listen::on_message, this);
  }
  ~Listen() { lcm_.unsubscribe(subscription_); }
  Listen(const Listen&) = delete;
  Listen& operator=(const Listen&) = delete;

 private:
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) { handler_(rbuf); }
  lcm::LCM& lcm_;
  Handler handler_;
  lcm::Subscription* subscription_ = nullptr;
};

}  // namespace

struct LcmClient::Impl {
  ClientOptions options;
  lcm::LCM lcm;
  std::mt19937_64 rng{std::random_device{}()};
  Clock::time_point last_send{};
  double last_round_trip_ms = 0.0;
  std::vector<protocol::CommandKey> keys;  // the first signs

  explicit Impl(ClientOptions o) : options(std::move(o)), lcm(options.lcm_url) {
    if (const std::string problem = protocol::payload_id_problem(options.payload_id); !problem.empty())
      throw InputError("--payload", "payload", problem);
    if (!options.key_file.empty()) keys = protocol::read_key_file(options.key_file);
    if (!lcm.good()) throw InputError("--lcm-url", "lcm-url", fmt::format("LCM cannot open '{}'", options.lcm_url));
  }

  std::string channel(Channel c) const { return protocol::channel_name(options.payload_id, c); }
  std::int64_t new_request_id() {
    std::int64_t id = 0;
    while (id <= 0) id = static_cast<std::int64_t>(rng() >> 1);
    return id;
  }
  // Handles messages for at most `seconds` (returns earlier when one arrives).
  void handle_for(double seconds) { lcm.handleTimeout(std::max(1, static_cast<int>(seconds * 1000))); }
};

LcmClient::LcmClient(ClientOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}
LcmClient::~LcmClient() = default;

double LcmClient::last_round_trip_ms() const { return impl_->last_round_trip_ms; }

std::optional<command_ack_t> LcmClient::command(const std::string& verb, const std::vector<std::string>& args) {
  command_t c;
  c.schema = 1;
  c.request_id = impl_->new_request_id();
  c.payload_id = impl_->options.payload_id;
  c.verb = verb;
  c.args = args;
  c.n_args = static_cast<std::int32_t>(args.size());
  c.auth_size = 0;
  c.utime = realtime_us();
  if (!impl_->keys.empty()) protocol::sign_command(c, impl_->keys.front());
  std::optional<command_ack_t> answer;
  const Listen acks(impl_->lcm, impl_->channel(Channel::ack), [&](const lcm::ReceiveBuffer* rbuf) {
    auto ack = decode<command_ack_t>(rbuf);
    if (ack && ack->request_id == c.request_id && !answer) {
      answer = std::move(ack);
      impl_->last_round_trip_ms = 1e3 * seconds_since(impl_->last_send);
    }
  });
  const auto start = Clock::now();
  impl_->last_send = start - std::chrono::seconds(1);
  while (!answer && seconds_since(start) < impl_->options.timeout_s) {
    if (seconds_since(impl_->last_send) >= 0.25) {
      impl_->last_send = Clock::now();
      impl_->lcm.publish(impl_->channel(Channel::command), &c);
    }
    impl_->handle_for(0.05);
  }
  return answer;
}

namespace {

Eigen::Isometry3d isometry_of(const double* position, const double* orientation) {
  const Eigen::Quaterniond q(orientation[0], orientation[1], orientation[2], orientation[3]);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d p(position[0], position[1], position[2]);
  if (!(std::abs(q.norm() - 1.0) <= 1e-3) || !p.allFinite()) return t;  // NaN fails the first test too
  t.linear() = q.normalized().toRotationMatrix();
  t.translation() = p;
  return t;
}

}  // namespace

Eigen::Isometry3d map_from_odometry(const frame_t& frame) { return isometry_of(frame.position, frame.orientation); }

Eigen::Isometry3d map_from_tiles(const frame_t& frame) {
  return frame.schema >= 2 ? isometry_of(frame.tiles_position, frame.tiles_orientation) : map_from_odometry(frame);
}

bool place_downloaded_points(std::vector<protocol::MapPoint>& points, const std::optional<frame_t>& frame) {
  const Eigen::Isometry3d placed = frame ? map_from_tiles(*frame) : Eigen::Isometry3d::Identity();
  if (placed.isApprox(Eigen::Isometry3d::Identity())) return false;
  for (protocol::MapPoint& p : points) {
    const Eigen::Vector3d q = placed * Eigen::Vector3d(p.x, p.y, p.z);
    p.x = q.x();
    p.y = q.y();
    p.z = q.z();
  }
  return true;
}

void LcmClient::follow(const FollowHandlers& handlers, const std::function<bool()>& until) {
  // Subscribes `channel` for as long as the follow lasts, when `handler` is set.
  const auto listen = [this]<typename Message>(Channel channel, const std::function<void(const Message&)>& handler) {
    std::unique_ptr<Listen> l;  // on the heap: LCM holds its address
    if (handler)
      l = std::make_unique<Listen>(impl_->lcm, impl_->channel(channel), [&handler](const lcm::ReceiveBuffer* rbuf) {
        if (auto m = decode<Message>(rbuf)) handler(*m);
      });
    return l;
  };
  const auto poses = listen(Channel::pose, handlers.pose);
  const auto statuses = listen(Channel::status, handlers.status);
  const auto index = listen(Channel::tile_index, handlers.tile_index);
  const auto segments = listen(Channel::tile, handlers.tile_segment);
  const auto grid = listen(Channel::grid, handlers.grid_patch);
  const auto frames = listen(Channel::frame, handlers.frame);
  const auto graph_paths = listen(Channel::graph_path, handlers.graph_path);
  const auto loop_statuses = listen(Channel::loops, handlers.loop_status);
  while (!until()) impl_->handle_for(0.05);
}

std::int64_t LcmClient::request_tiles(const std::string& session,
                                      const std::vector<protocol::MissingSegment>& missing, bool want_index) {
  tile_request_t request;
  request.schema = 2;  // versions[] are the versions held
  request.request_id = impl_->new_request_id();
  request.utime = realtime_us();
  request.payload_id = impl_->options.payload_id;
  request.session_id = session;
  request.want_index = want_index;
  const std::size_t n = std::min(missing.size(), kMaxRequestEntries);
  for (std::size_t i = 0; i < n; ++i) {
    request.tile_ids.push_back(missing[i].tile_id);
    request.versions.push_back(missing[i].held_version);
    request.chunks.push_back(missing[i].segment);
  }
  request.n_entries = static_cast<std::int32_t>(n);
  impl_->lcm.publish(impl_->channel(Channel::tile_request), &request);
  return request.request_id;
}

LcmClient::DownloadResult LcmClient::download(const std::string& session, protocol::TileAssembler& tiles,
                                              const std::function<void(std::size_t, std::size_t)>& progress) {
  DownloadResult result;
  std::string locked = session;  // "" until the daemon names its current session
  std::set<std::int32_t> parts;
  std::int32_t n_parts = -1;
  std::string index_error;
  std::set<std::int64_t> my_requests;  // other clients' errors are not ours
  auto last_progress = Clock::now();
  const Listen index(impl_->lcm, impl_->channel(Channel::tile_index), [&](const lcm::ReceiveBuffer* rbuf) {
    const auto m = decode<tile_index_t>(rbuf);
    if (!m || m->payload_id != impl_->options.payload_id) return;
    if (!m->error.empty()) {
      if (my_requests.count(m->request_id) != 0) index_error = m->error;
      return;
    }
    if (locked.empty()) locked = m->session_id;
    if (m->session_id != locked) return;
    for (std::size_t i = 0; i < m->tile_ids.size(); ++i)
      tiles.note_index(m->tile_ids[i], m->versions[i], m->n_chunks[i]);
    if (!m->full) return;  // a broadcast of changed tiles only
    parts.insert(m->part);
    n_parts = m->n_parts;
    last_progress = Clock::now();
  });
  auto last_chunk = Clock::now();
  const Listen chunks(impl_->lcm, impl_->channel(Channel::tile), [&](const lcm::ReceiveBuffer* rbuf) {
    const auto m = decode<tile_segment_t>(rbuf);
    if (!m || locked.empty() || m->session_id != locked) return;
    const auto outcome = tiles.add_segment(*m);
    last_chunk = Clock::now();
    if (outcome == protocol::SegmentOutcome::stored || outcome == protocol::SegmentOutcome::completed) {
      last_progress = last_chunk;
      progress(tiles.segments_have(), tiles.segments_wanted());
    }
  });
  std::optional<frame_t> any_frame;  // the newest, of whichever session, until `locked` is known
  const Listen frames(impl_->lcm, impl_->channel(Channel::frame), [&](const lcm::ReceiveBuffer* rbuf) {
    auto m = decode<frame_t>(rbuf);
    if (m && m->payload_id == impl_->options.payload_id) any_frame = std::move(m);
  });
  const auto index_complete = [&] { return n_parts > 0 && static_cast<std::int32_t>(parts.size()) >= n_parts; };

  auto last_send = Clock::now() - std::chrono::seconds(10);
  while (true) {
    if (!index_error.empty()) {
      result.error = index_error;
      break;
    }
    if (seconds_since(last_progress) > impl_->options.timeout_s) {
      result.error = index_complete()
                         ? fmt::format("no tile data for {} s ({} of {} segments)", impl_->options.timeout_s,
                                       tiles.segments_have(), tiles.segments_wanted())
                         : fmt::format("no payload '{}' answered within {} s", impl_->options.payload_id,
                                       impl_->options.timeout_s);
      break;
    }
    if (index_complete() && tiles.complete()) {
      result.ok = true;
      // The frame comes with each status (2 Hz) for the daemon's current or last session only.
      const auto done = Clock::now();
      while ((!any_frame || any_frame->session_id != locked) && seconds_since(done) < kFrameWaitS) impl_->handle_for(0.05);
      if (any_frame && any_frame->session_id == locked) result.frame = any_frame;
      break;
    }
    // Ask again once the stream has been quiet for a moment: what is still
    // missing then was lost (or never sent).
    const bool quiet = seconds_since(last_chunk) > 0.3 && seconds_since(last_send) > 0.5;
    if (quiet) {
      my_requests.insert(request_tiles(locked, tiles.missing(kMaxRequestEntries), !index_complete()));
      ++result.requests;
      last_send = Clock::now();
    }
    impl_->handle_for(0.05);
  }
  return result;
}

LcmClient::FileResult LcmClient::fetch_file(const std::string& session, const std::string& path) {
  FileResult result;
  result.session = session;
  std::vector<std::optional<std::string>> chunks;  // sized once the first answer says how many
  std::size_t have = 0;
  std::set<std::int64_t> my_requests;
  std::string error;
  auto last_progress = Clock::now();
  auto last_chunk = Clock::now();
  const Listen listen(impl_->lcm, impl_->channel(Channel::file), [&](const lcm::ReceiveBuffer* rbuf) {
    const auto m = decode<file_chunk_t>(rbuf);
    if (!m || m->payload_id != impl_->options.payload_id || my_requests.count(m->request_id) == 0) return;
    last_chunk = Clock::now();
    if (!m->error.empty()) {
      error = m->error;
      return;
    }
    if (m->n_chunks <= 0 || m->chunk < 0 || m->chunk >= m->n_chunks || m->size != static_cast<std::int32_t>(m->data.size()))
      return;
    if (chunks.empty()) {
      chunks.resize(static_cast<std::size_t>(m->n_chunks));
      result.session = m->session_id;
    }
    if (m->session_id != result.session || chunks.size() != static_cast<std::size_t>(m->n_chunks)) return;
    auto& slot = chunks[static_cast<std::size_t>(m->chunk)];
    if (slot) return;
    slot.emplace(m->data.begin(), m->data.end());
    ++have;
    last_progress = last_chunk;
  });
  auto last_send = Clock::now() - std::chrono::seconds(10);
  while (true) {
    if (!error.empty()) {
      result.error = error;
      return result;
    }
    if (!chunks.empty() && have == chunks.size()) break;
    if (seconds_since(last_progress) > impl_->options.timeout_s) {
      result.error = chunks.empty() ? fmt::format("no payload '{}' answered within {} s", impl_->options.payload_id,
                                                  impl_->options.timeout_s)
                                    : fmt::format("no data for {} s ({} of {} chunks)", impl_->options.timeout_s, have,
                                                  chunks.size());
      return result;
    }
    if (seconds_since(last_chunk) > 0.3 && seconds_since(last_send) > 0.5) {
      // The first chunk still missing and the window after it.
      std::int32_t first = 0;
      while (static_cast<std::size_t>(first) < chunks.size() && chunks[static_cast<std::size_t>(first)]) ++first;
      file_request_t r;
      r.utime = realtime_us();
      r.schema = 1;
      r.request_id = impl_->new_request_id();
      r.payload_id = impl_->options.payload_id;
      r.session_id = result.session;
      r.path = path;
      r.first_chunk = first;
      r.n_chunks = protocol::kMaxChunksPerRequest;
      my_requests.insert(r.request_id);
      impl_->lcm.publish(impl_->channel(Channel::file_request), &r);
      ++result.requests;
      last_send = Clock::now();
    }
    impl_->handle_for(0.05);
  }
  for (const auto& c : chunks) result.bytes += *c;
  result.ok = true;
  return result;
}

}  // namespace adit::tools
