#include "adit/daemon/sessions.hpp"

#include <pthread.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cctype>
#include <charconv>
#include <iterator>
#include <ctime>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/common/clock.hpp"
#include "adit/common/error.hpp"
#include "adit/common/log.hpp"
#include "adit/common/quantile.hpp"
#include "adit/config/load.hpp"
#include "adit/protocol/map_export.hpp"
#include "adit/protocol/tile_codec.hpp"
#include "adit/daemon/loop_closure_stage.hpp"
#include "adit/daemon/loop_status.hpp"
#include "adit/daemon/prior_localiser.hpp"
#include "adit/daemon/map_files.hpp"
#include "adit/daemon/durable_file.hpp"
#include "adit/daemon/can_feed.hpp"
#include "adit/drivers/can/bus_status.hpp"
#include "adit/drivers/pcap_replay.hpp"
#include "adit/daemon/journal_writer.hpp"
#include "adit/daemon/products_worker.hpp"
#include "adit/daemon/session_frame.hpp"
#include "adit/daemon/session_recovery.hpp"
#include "adit/daemon/tile_spill.hpp"
#include "adit/slam/tum.hpp"

namespace adit::daemon {

namespace {

// summary.json's "imu": the IMU source's figures (imu_stats.hpp).
// The CAN feed's frames and its bus's health; null without a CAN feed.
nlohmann::json can_summary(const CanFeedStats* can) {
  if (can == nullptr) return nullptr;
  return {{"frames", can->frames.load()},
          {"dropped", can->dropped.load()},
          {"error_frames", can->error_frames.load()},
          {"bus_off", can->bus_off.load()},
          {"recoveries", can->recoveries.load()},
          {"bus_state_at_end", std::string(drivers::can::bus_state_name(static_cast<drivers::can::BusState>(can->bus_state.load())))}};
}

nlohmann::json imu_summary(const ImuStats& imu) {
  nlohmann::json problems = nlohmann::json::object();
  for (std::size_t k = 0; k < kImuProblemKinds; ++k) {
    const auto p = static_cast<ImuProblem>(k);
    problems[std::string(to_string(p))] = imu.count(p);
  }
  const double spread = imu.clock_spread_s.load();
  return {{"packets", imu.packets.load()},
          {"readings", imu.samples.load()},
          {"with_gyro", imu.gyro_samples.load()},
          {"dropped", imu.dropped.load()},
          {"rate_hz", imu.rate_hz.load()},
          {"longest_gap_s", imu.longest_gap_s.load()},
          {"time_offset_s", imu.time_offset_s.load()},
          {"clock_spread_s", std::isfinite(spread) ? nlohmann::json(spread) : nlohmann::json(nullptr)},
          {"problems", problems}};
}

// summary.json's "prior_map": whether the odometry localised against the
// prior and anchored to it (prior_frame.json then places the session in it).
nlohmann::json prior_summary(const PriorLocaliser* prior, const std::string& source) {
  if (prior == nullptr) return {{"enabled", false}};
  const PriorLocaliserStats& s = prior->stats();
  const bool anchored = s.anchored.load();
  return {{"enabled", true}, {"source", source}, {"anchored", anchored},
          {"anchored_after_s", anchored ? nlohmann::json(s.anchored_after_s.load()) : nlohmann::json(nullptr)},
          {"tries", s.tries.load()}, {"failed_tries", s.failures.load()},
          {"scans_without_up", s.scans_without_up.load()}, {"hinted_tries", s.hinted_tries.load()},
          {"unconfirmed_tries", s.unconfirmed.load()}};
}

// The running session's map frame for frame_t: the prior's once found, else
// gravity's level once the odometry has an up (`level`), the tiles placed by
// the graph's latest correction when they follow it (`loops`:
// map.loops_move_map), the poses by the map's `refinement` of the odometry
// (map_frame.hpp).
MapFrame session_frame(const PriorLocaliser* prior, const std::optional<Eigen::Isometry3d>& level,
                       const LoopClosureStage* loops, const Eigen::Isometry3d& refinement) {
  const std::shared_ptr<const slam::CorrectionTrack> track = loops != nullptr ? loops->live().latest() : nullptr;
  const std::optional<Eigen::Isometry3d> anchor = prior != nullptr ? prior->anchor() : std::nullopt;
  return map_frame_of(export_frame(anchor, anchor ? std::nullopt : level),
                      track != nullptr && !track->empty() ? std::optional(track->corrections().back()) : std::nullopt,
                      refinement)
      .value_or(MapFrame{});
}

// The map file (map.ply, else .las, else .pcd: session.exports) of the newest
// session under `root` that was finished (its summary.json written: stopped,
// or recovered after a crash); empty when none. Session ids are UTC times, so
// the greatest name is the newest.
std::filesystem::path newest_session_map(const std::filesystem::path& root) {
  std::filesystem::path newest;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(root, ec)) {
    const std::filesystem::path& d = entry.path();
    if (!entry.is_directory() || !std::filesystem::exists(d / "summary.json")) continue;
    if (!newest.empty() && d.filename() <= newest.parent_path().filename()) continue;
    for (const char* name : {"map.ply", "map.las", "map.pcd"})
      if (std::filesystem::exists(d / name)) {
        newest = d / name;
        break;
      }
  }
  return newest;
}

// summary.json's "loops": what loop closure found, accepted and refused, and
// the correction the graph applied to the map (docs/LOOPS.md).
nlohmann::json loops_summary(const LoopClosureStage* loops, const slam::CorrectionTrack& track, bool moved) {
  if (loops == nullptr) return {{"enabled", false}};
  const slam::LoopClosureStats& s = loops->closer().stats();
  nlohmann::json by_outcome = nlohmann::json::object();
  for (const auto& [outcome, count] : loops->closer().outcomes()) by_outcome[outcome] = count;
  nlohmann::json events = nlohmann::json::array();
  for (const slam::LoopEvent& e : loops->closer().events()) {
    if (events.size() < 200)  // the first ones; the counts cover all
      events.push_back({{"query", e.query}, {"candidate", e.candidate}, {"descriptor_distance", e.descriptor_distance},
                        {"outcome", e.outcome}, {"inlier_ratio", e.inlier_ratio}, {"rmse_m", e.rmse_m},
                        {"conditioning", e.conditioning}});
  }
  // Every loop in the graph (events' "waiting" may have been accepted later):
  // T_from⁻¹·T_to as x y z qx qy qz qw and its 6×6 information ([v; ω]; a
  // partial loop's is singular along its free axis), for `adit eval loops`.
  nlohmann::json loop_edges = nlohmann::json::array();
  for (const slam::PoseGraphEdge& e : loops->closer().graph().edges) {
    if (e.kind != slam::EdgeKind::loop) continue;
    const Eigen::Vector3d t = e.measurement.translation();
    const Eigen::Quaterniond q(e.measurement.linear());
    const std::vector<double> information(e.information.data(), e.information.data() + 36);  // symmetric
    loop_edges.push_back({{"from", e.from}, {"to", e.to}, {"measurement", {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()}},
                          {"information", information}});
  }
  const Eigen::Isometry3d last = track.empty() ? Eigen::Isometry3d::Identity() : track.corrections().back();
  return {{"enabled", true},
          {"map_moved", moved},
          {"keyframes", s.keyframes},
          {"keyframes_not_searched", s.keyframes_not_searched},
          {"candidates", s.candidates},
          {"verified", s.verified},
          {"accepted", s.accepted},
          {"rejected", s.rejected_verification + s.rejected_inconsistent},
          {"rejected_by_verification", s.rejected_verification},
          {"readings_set_aside_by_heading", s.set_aside_readings},
          {"rejected_unreadable", s.rejected_unreadable},
          {"scans", {{"in_ram_bytes", loops->closer().scans().bytes_in_ram()},
                     {"on_disk", loops->closer().scans().spilled()},
                     {"write_errors", loops->closer().scans().write_errors()},
                     {"read_errors", loops->closer().scans().read_errors()}}},
          {"rejected_inconsistent", s.rejected_inconsistent},
          {"unconfirmed", loops->closer().unconfirmed()},
          {"verified_partial", s.partial},
          {"outcomes", by_outcome},
          {"optimizations", s.optimizations},
          {"last_optimization_s", s.last_optimization_s},
          {"optimization_s_total", s.optimization_s_total},
          {"optimization_iterations", s.optimization_iterations_total},
          {"refine_s", loops->refine_time_s()},
          {"search_ms_mean", s.keyframes > 0 ? 1e3 * s.search_s_total / static_cast<double>(s.keyframes) : 0.0},
          {"search_ms_max", 1e3 * s.search_s_max},
          {"verification_ms_mean", s.candidates > 0 ? 1e3 * s.verification_s_total / static_cast<double>(s.candidates) : 0.0},
          {"verification_ms_max", 1e3 * s.verification_s_max},
          {"correction", {{"last_translation_m", last.translation().norm()},
                          {"last_rotation_deg", Eigen::AngleAxisd(last.linear()).angle() * 180.0 / M_PI},
                          {"max_translation_m", track.max_translation_m()},
                          {"max_rotation_deg", track.max_rotation_rad() * 180.0 / M_PI}}},
          {"events", events},
          {"edges", loop_edges}};
}

// summary.json's "grid_live": the live 2D grid as the tablet had it, written
// as grid_live.pgm / .yaml (null without grid.enabled).
nlohmann::json live_grid_summary(const slam::LiveGrid* grid, double resolution_m, std::uintmax_t file_bytes,
                                 const std::vector<double>& insert_ms) {
  if (grid == nullptr) return nullptr;
  return {{"patches", grid->patch_count()}, {"resolution_m", resolution_m},
          {"scans", grid->counts().scans}, {"memory_bytes", grid->memory_bytes()}, {"file_bytes", file_bytes},
          {"patches_frozen", grid->frozen_count()}, {"freezes", grid->counts().freezes}, {"thaws", grid->counts().thaws},
          {"insert_ms_median", quantile(insert_ms, 0.5)}, {"insert_ms_p99", quantile(insert_ms, 0.99)}};
}

// summary.json's "journal": what the crash-safety journal wrote (it is
// removed once the summary is on the disk).
nlohmann::json journal_summary(const JournalWriter* journal) {
  if (journal == nullptr) return {{"enabled", false}};
  const JournalStats& j = journal->stats();
  return {{"enabled", true}, {"records", j.records.load()}, {"bytes", j.bytes.load()}, {"syncs", j.syncs.load()},
          {"lost_records", j.lost_records.load()}, {"fault", journal->fault()}};
}

}  // namespace
namespace {

// pose_t.FLAG_*: kept here as numbers so this file needs no LCM header.
constexpr std::int32_t kFlagValid = 1;
constexpr std::int32_t kFlagDegenerate = 2;
constexpr std::int32_t kFlagHeld = 4;
constexpr std::int32_t kFlagLost = 8;
constexpr std::int32_t kFlagRelocalised = 16;

std::string utc_id() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  return fmt::format("{:04}{:02}{:02}T{:02}{:02}{:02}Z", utc.tm_year + 1900, utc.tm_mon + 1, utc.tm_mday, utc.tm_hour,
                     utc.tm_min, utc.tm_sec);
}

std::int64_t disk_free_bytes(const std::filesystem::path& dir) {
  struct statvfs s {};
  if (statvfs(dir.c_str(), &s) != 0) return -1;
  return static_cast<std::int64_t>(s.f_bavail) * static_cast<std::int64_t>(s.f_frsize);
}

}  // namespace

PoseSample pose_sample_of(const slam::OdometryResult& r) {
  PoseSample p;
  p.utime = r.stamp_ns / 1000;
  const Eigen::Vector3d& t = r.pose.translation();
  p.position = {t.x(), t.y(), t.z()};
  const Eigen::Quaterniond q(r.pose.linear());
  p.orientation = {q.w(), q.x(), q.y(), q.z()};
  // Row-major; the odometry's tangent order [v; ω] is (x, y, z, roll, pitch,
  // yaw) to first order, which is what pose_t documents.
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) p.covariance[static_cast<std::size_t>(6 * i + j)] = r.covariance(i, j);
  p.flags = (r.valid ? kFlagValid : 0) | (r.status == slam::OdometryStatus::degenerate ? kFlagDegenerate : 0) |
            (r.status == slam::OdometryStatus::too_few_points || r.status == slam::OdometryStatus::lost ? kFlagHeld : 0) |
            (r.status == slam::OdometryStatus::lost ? kFlagLost : 0) |
            (r.status == slam::OdometryStatus::relocalised ? kFlagRelocalised : 0);
  return p;
}

Sessions::Sessions(const config::Config& config, Outputs outputs)
    : config_(config), outputs_(std::move(outputs)), root_(std::filesystem::path(config.payload.state_dir) / "sessions") {
  standby_ = build_pipeline();
  if (config_.session.products || config_.session.join_previous)
    products_ = std::make_unique<ProductsWorker>(AfterSessionSteps{config_.session.products, config_.session.join_previous, {}});
  if (!interrupted_sessions(root_).empty()) recoverer_ = std::thread([this] { recover_interrupted(); });
}

// Niced like the loop closure: a new session may start meanwhile and its
// odometry comes first. Each session's report goes to the log and the status.
void Sessions::recover_interrupted() {
  constexpr int kNice = 10;
  if (setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), kNice) != 0)
    log::warn("recovery: cannot lower its priority");
  pthread_setname_np(pthread_self(), "adit-recovery");
  for (const std::filesystem::path& dir : interrupted_sessions(root_)) {
    log::warn("session {}: was cut short (no summary.json): rebuilding it from its journal", dir.filename().string());
    const RecoveryReport report = recover_session(dir, config_.session.exports, config_.map.tile_size_m);
    const std::string text = describe(report);
    if (report.recovered) log::warn("{}", text);
    else log::error("{}", text);
    const std::lock_guard lock(mutex_);
    recovery_notice_ = text;
  }
}

std::unique_ptr<Pipeline> Sessions::build_pipeline() const {
  PipelineOptions options;
  if (outputs_.pose) {
    options.sinks.pose = [pose = outputs_.pose](const slam::OdometryResult& r) { pose(pose_sample_of(r)); };
  }
  options.sinks.imu_pose = outputs_.imu_pose;
  options.sinks.tile_backlog = outputs_.tile_backlog;
  if (outputs_.tile) {
    options.sinks.tile = [tile = outputs_.tile](const slam::TileCoord& c, std::size_t first_point,
                                                std::span<const slam::MapSample> points) {
      return tile(TileUpdate{realtime_us(), protocol::TileKey{c.x, c.y, c.z}, map_points_of(points), first_point});
    };
  }
  if (outputs_.grid) {
    options.sinks.grid = [grid = outputs_.grid, c = config_.grid](slam::GridPatchCoord p, std::int32_t version,
                                                                   std::span<const std::int8_t> cells, std::size_t n) {
      grid(GridPatchUpdate{realtime_us(), p.x, p.y, version, static_cast<std::int32_t>(n),
                           static_cast<float>(c.resolution_m), c.patch_cells, {cells.begin(), cells.end()}});
    };
  }
  if (config_.prior_map.previous_session && config_.prior_map.dir.empty())
    options.prior_session_map = newest_session_map(root_);
  return std::make_unique<Pipeline>(config_, options);
}

Sessions::~Sessions() {
  stop_and_wait();
  if (products_) products_->stop();  // waits for the session being made, drops the rest
  if (recoverer_.joinable()) recoverer_.join();
}

std::string Sessions::start() {
  const std::lock_guard lock(mutex_);
  try {
    return start_locked();
  } catch (...) {
    start_failure_ = std::current_exception();
    throw;
  }
}

std::exception_ptr Sessions::take_start_failure() {
  const std::lock_guard lock(mutex_);
  return std::exchange(start_failure_, nullptr);
}

std::string Sessions::start_locked() {
  if (pipeline_ || finishing_) throw std::runtime_error("a session is still running or being written");
  std::string id = utc_id();
  for (int n = 2; std::filesystem::exists(root_ / id); ++n) id = fmt::format("{}-{}", utc_id(), n);
  const std::filesystem::path dir = root_ / id;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir.string(), "payload.state_dir", "cannot create the session folder: " + ec.message());

  std::unique_ptr<Pipeline> pipeline = std::move(standby_);
  SessionFiles files;
  files.trajectory_file = dir / "trajectory.tum";
  files.map_trajectory_file = dir / "map_trajectory.tum";  // the poses the map was built at
  files.tiles_dir = dir / "tiles";          // tiles the sensor has left go there during the session
  files.keyframes_dir = dir / "keyframes";  // and the scans of keyframes it has left
  if (config_.session.record_lidar && config_.lidar.source != config::LidarSource::scan_dir)
    files.record_file = dir / "lidar.pcap";  // a directory of scans has no packets to record
  if (config_.can.enabled && config_.can.record) files.can_record_file = dir / "can.log";
  if (config_.session.journal) {
    files.journal_file = dir / "journal.adj";
    files.journal_header = nlohmann::json{{"session", id},
                                          {"tile_size_m", config_.map.tile_size_m},
                                          {"voxel_m", config_.map.voxel_m},
                                          {"min_hits", config_.map.min_hits},
                                          {"lidar", config_.lidar.model},
                                          {"started_utime", realtime_us()}}
                               .dump();
  }
  try {
    if (!pipeline) pipeline = build_pipeline();  // the last one could not be built ahead
    if (pipeline->prior_localiser() != nullptr) files.prior_frame_file = dir / "prior_frame.json";
    files.level_frame_file = dir / "level_frame.json";
    pipeline->start(files);
  } catch (...) {
    std::filesystem::remove_all(dir, ec);  // nothing was recorded: leave no empty session behind
    throw;
  }
  for (std::string& w : pipeline->warnings()) warnings_.push_back(std::move(w));
  {
    std::ofstream(dir / "config.yaml") << config::to_yaml(config_);
  }
  pipeline_ = std::move(pipeline);
  id_ = id;
  dir_ = dir;
  recovery_notice_.clear();
  stop_requested_ = false;
  end_reported_ = false;
  last_sample_ns_ = 0;
  log::info("session {}: mapping, files in {}", id, dir.string());
  return id;
}

void Sessions::request_stop() { stop_requested_ = true; }

bool Sessions::poll() {
  const std::lock_guard lock(mutex_);
  if (finisher_.joinable() && !finishing_) finisher_.join();
  if (!pipeline_ || finisher_.joinable()) return false;
  if (stop_requested_) {
    pipeline_->end_source();
    finishing_ = true;
    finisher_ = std::thread([this, p = std::move(pipeline_), id = id_, dir = dir_]() mutable {
      finish(std::move(p), std::move(id), std::move(dir));
    });
    return false;
  }
  if (end_reported_ || !pipeline_->drained()) return false;
  end_reported_ = true;  // a replay ran out: the caller asks for the stop, once
  return true;
}

void Sessions::stop_and_wait() {
  request_stop();
  while (true) {
    poll();
    {
      const std::lock_guard lock(mutex_);
      if (!pipeline_ && !finishing_) {
        if (finisher_.joinable()) finisher_.join();
        return;
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

void Sessions::finish(std::unique_ptr<Pipeline> pipeline, std::string id, std::filesystem::path dir) {
  pipeline->join();  // end_source() was called: every stage drains first
  const PipelineStats& s = pipeline->stats();
  const PipelineTimings& t = pipeline->timings();
  const slam::TiledVoxelMap& map = pipeline->map();
  nlohmann::json files = nlohmann::json::array({"trajectory.tum", "map_trajectory.tum", "config.yaml"});
  try {
    // The tiles still in RAM join those the mapping thread evicted to tiles/
    // during the session; then the map files, streamed tile by tile (a long
    // session's map does not fit in RAM whole).
    const protocol::TileParams params = stored_tile_params(config_.map.tile_size_m);
    TileSpill resident_tiles(dir / "tiles", params);
    const TileSpill* spill = pipeline->tile_spill();  // what the mapping thread evicted (and restored)
    std::vector<slam::MapSample> whole;
    for (const slam::TileCoord& c : map.tile_coords()) {
      std::string problem;
      if (map.stored_points(c) == 0) {
        problem = resident_tiles.write(c, map.tile(c));
      } else if (!map.tile(c).empty()) {  // a restored tile with new points: its file gets them
        problem = spill == nullptr ? "restored tile without a tile folder" : spill->whole_tile(map, c, whole);
        if (problem.empty()) problem = resident_tiles.write(c, whole);
      }
      if (!problem.empty()) throw std::runtime_error(problem);
    }
    files.push_back("tiles/");
    std::vector<slam::TileCoord> coords = map.tile_coords();
    const std::vector<slam::TileCoord> evicted = map.evicted_coords();
    coords.insert(coords.end(), evicted.begin(), evicted.end());
    std::sort(coords.begin(), coords.end());
    // With loop closure the map's points move by the graph's correction
    // (only when a loop was accepted: otherwise the correction is identity).
    const LoopClosureStage* loops = pipeline->loop_closure();
    const slam::CorrectionTrack track = loops != nullptr ? loops->correction() : slam::CorrectionTrack{};
    const bool corrected = loops != nullptr && config_.map.loops_move_map && loops->closer().stats().accepted > 0;
    // Anchored to a prior map, every export is in the prior's frame; else,
    // when the odometry measured gravity, in the odometry frame levelled by
    // it (the mapping thread's last level, also in level_frame.json, which a
    // recovery after a crash reads: session_frame.hpp).
    const std::optional<Eigen::Isometry3d> anchor =
        pipeline->prior_localiser() != nullptr ? pipeline->prior_localiser()->anchor() : std::nullopt;
    const std::optional<Eigen::Isometry3d> level = anchor ? std::nullopt : pipeline->level();
    if (std::filesystem::exists(dir / "level_frame.json")) files.push_back("level_frame.json");
    const ExportFrame frame = export_frame(anchor, level);
    const Eigen::Isometry3d& placed_by = frame.from_odometry;
    const bool placed = frame.source != ExportSource::odometry;
    double margin = 0.0;  // the corner stays at or below every moved point
    if (corrected) {
      double reach = 0.0;
      for (const slam::TileCoord& c : coords)
        reach = std::max(reach, config_.map.tile_size_m * (std::abs(c.x) + std::abs(c.y) + std::abs(c.z) + 3.0));
      margin = track.max_translation_m() + track.max_rotation_rad() * reach + 1.0;
    }
    std::vector<slam::MapSample> read_back;
    std::vector<slam::MapSample> moved;
    std::vector<slam::MapSample> moved_out;  // into the export frame
    // The tiles as the graph placed them last go to tiles_graph/ too, whole
    // before it takes that name: a download after a restart is served from
    // there (load_tiles), as the live tiles were. A failure there (a full
    // disk) leaves the map files be: the first one is kept and said below.
    const std::filesystem::path graph_dir = dir / kGraphTilesFolder;
    const std::filesystem::path graph_partial = dir / kGraphTilesPartialFolder;
    std::error_code ignored;
    std::filesystem::remove_all(graph_partial, ignored);
    std::filesystem::remove_all(graph_dir, ignored);
    TileSpill graph_tiles(graph_partial, params);
    std::string graph_problem;
    const auto read_tile = [&](const slam::TileCoord& c, std::vector<protocol::MapPoint>& points) {
      std::span<const slam::MapSample> samples = map.tile(c);
      if (map.is_evicted(c) || map.stored_points(c) > 0) {  // its file is whole now: read it back
        const bool rewritten = !map.is_evicted(c) && !map.tile(c).empty();
        const std::string problem = rewritten         ? resident_tiles.read(c, read_back)
                                    : spill == nullptr ? "evicted tile without a tile folder"
                                                       : spill->read(c, read_back);
        if (!problem.empty()) throw std::runtime_error(problem);
        samples = read_back;
      }
      if (corrected) {
        slam::correct_samples(samples, &track, Eigen::Isometry3d::Identity(), moved);
        samples = moved;
        if (graph_problem.empty()) graph_problem = graph_tiles.write(c, samples);
      }
      if (placed) {
        slam::correct_samples(samples, nullptr, placed_by, moved_out);
        samples = moved_out;
      }
      points = map_points_of(samples);
    };
    for (std::string& name : write_map_files(dir, config_.session.exports, map.size(),
                                             map_corner(coords, config_.map.tile_size_m, margin, placed_by), coords, read_tile))
      files.push_back(std::move(name));
    if (corrected) {
      try {
        if (!graph_problem.empty()) throw std::runtime_error(graph_problem);
        std::filesystem::create_directories(graph_partial);  // also for a map of no tiles
        write_graph_correction(graph_partial / kGraphCorrectionFile,
                               track.empty() ? Eigen::Isometry3d::Identity() : track.corrections().back());
        std::filesystem::rename(graph_partial, graph_dir);
        files.push_back(std::string(kGraphTilesFolder) + "/");
      } catch (const std::exception& e) {
        std::filesystem::remove_all(graph_partial, ignored);
        log::warn("session {}: {}/ not written ({}); a download after a restart gets tiles/, not moved by the loops",
                  id, kGraphTilesFolder, e.what());
      }
    }
    slam::Trajectory keyframes;  // the graph's poses with loop closure (the same keyframes, in order)
    const std::vector<Eigen::Isometry3d>* graph = loops != nullptr ? &loops->closer().poses() : nullptr;
    for (std::size_t i = 0; i < pipeline->keyframes().size(); ++i) {
      const slam::Keyframe& k = pipeline->keyframes()[i];
      keyframes.stamps.push_back(1e-9 * static_cast<double>(k.stamp_ns));
      keyframes.poses.push_back(placed_by * (graph != nullptr && i < graph->size() ? (*graph)[i] : k.pose));
    }
    // The trajectories as the map files: moved by the graph, in the export frame.
    place_session_trajectories(dir, frame, corrected ? &track : nullptr);
    slam::write_tum(dir / "keyframes.tum", keyframes);
    files.push_back("keyframes.tum");
    std::uintmax_t grid_bytes = 0;
    if (const slam::LiveGrid* grid = pipeline->grid(); grid != nullptr) {
      grid_bytes = write_live_grid(dir / "grid_live", *grid);
      if (grid_bytes > 0) {
        files.push_back("grid_live.pgm");
        files.push_back("grid_live.yaml");
      }
    }
    if (s.spilled_keyframes.load() > 0) files.push_back("keyframes/");
    const JournalWriter* journal = pipeline->journal();
    if (s.recorded_datagrams > 0) files.push_back("lidar.pcap");
    for (int part = 1; std::filesystem::exists(drivers::pcap_part(dir / "lidar.pcap", part)); ++part)
      files.push_back(drivers::pcap_part("lidar.pcap", part).string());
    if (config_.can.enabled && config_.can.record) files.push_back("can.log");
    const nlohmann::json summary = {
        {"session", id},
        {"lidar", {{"model", config_.lidar.model}, {"datagrams", s.datagrams.load()},
                   {"dropped_packets", s.dropped_packets.load()}, {"socket_drops", s.socket_drops.load()},
                   {"bad_packets", s.bad_packets.load()},
                   {"missing_packets", s.missing_packets.load()}, {"duplicate_packets", s.duplicate_packets.load()},
                   {"late_packets", s.late_packets.load()}, {"resyncs", s.resyncs.load()},
                   {"silences", s.silences.load()}, {"longest_silence_s", 1e-9 * static_cast<double>(s.longest_silence_ns.load())},
                   {"recorded_datagrams", s.recorded_datagrams.load()}, {"recorded_bytes", s.recorded_bytes.load()},
                   {"recording_stopped", s.recording_stopped.load() == 0
                                             ? nlohmann::json(nullptr)
                                             : nlohmann::json(to_string(static_cast<RecordingStop>(s.recording_stopped.load())))}}},
        {"scans", {{"total", s.scans.load()}, {"incomplete", s.incomplete_scans.load()},
                   {"dropped", s.dropped_scans.load()}, {"skipped_at_start", s.skipped_start_scans.load()}}},
        {"poses", {{"total", s.poses.load()}, {"invalid", s.invalid_poses.load()},
                   {"degenerate", s.degenerate_poses.load()}, {"lost", s.lost_poses.load()},
                   {"relocalised", s.relocalised_poses.load()}, {"searches_cut", s.searches_cut.load()},
                   {"with_wheel_prior", s.wheel_priors.load()},
                   {"wheels_missing", s.scans_without_wheels.load()},
                   {"wheels_held", s.scans_wheels_held.load()},
                   {"turned_by_gyro", s.gyro_priors.load()},
                   {"gyro_bias_still", s.gyro_still.load()},
                   {"gyro_refused", s.gyro_refused.load()},
                   {"with_gravity_prior", s.gravity_priors.load()},
                   {"gravity_missing", s.scans_without_gravity.load()}}},
        {"imu", imu_summary(s.imu)},
        {"can", can_summary(pipeline->can_stats())},
        {"host_clock", {{"steps", s.clock_steps.load()}, {"last_step_s", 1e-9 * static_cast<double>(s.last_clock_step_ns.load())}}},
        {"loops", loops_summary(loops, track, corrected)},
        {"prior_map", prior_summary(pipeline->prior_localiser(), pipeline->prior_source())},
        {"frame", frame_summary(frame)},
        {"journal", journal_summary(journal)},
        {"map", {{"points", map.size()}, {"tiles", map.tile_count()}, {"voxel_m", config_.map.voxel_m},
                 {"tile_size_m", config_.map.tile_size_m}, {"keyframes", pipeline->keyframes().size()},
                 {"mapped_scans", s.mapped_scans.load()}, {"dropped_scans", s.dropped_map_scans.load()},
                 {"evicted_tiles", s.evicted_tiles.load()}, {"restored_tiles", s.restored_tiles.load()},
                 {"compacted_tiles", s.compacted_tiles.load()},
                 {"peak_resident_tiles_mb", 1e-6 * static_cast<double>(s.map_bytes_peak.load())},
                 {"tiles_checked_for_loops", s.tiles_checked_for_loops.load()},
                 {"tiles_checked_by_corners", s.tiles_checked_by_corners.load()},
                 {"tiles_moved_by_loops", s.tiles_moved_by_loops.load()},
                 {"points_moved_by_loops", s.points_moved_by_loops.load()},
                 {"revisit_points", s.revisit_points.load()},
                 {"spilled_keyframes", s.spilled_keyframes.load()},
                 {"lost_candidates", s.lost_candidates.load()}, {"tile_file_errors", s.tile_file_errors.load()},
                 {"dropped_in_evicted", s.dropped_in_evicted.load()}}},
        {"grid_live", live_grid_summary(pipeline->grid(), config_.grid.resolution_m, grid_bytes, t.grid_ms)},
        {"timing", {{"odometry_ms_median", quantile(t.odometry_ms, 0.5)},
                    {"odometry_ms_p99", quantile(t.odometry_ms, 0.99)},
                    {"latency_ms_p99", quantile(t.latency_ms, 0.99)},
                    {"sensor_span_s", t.sensor_span_s}, {"duration_s", t.duration_s}}},
        {"files", files}};
    // Whole or not at all: a summary.json is what says the session is complete.
    write_durably(dir / "summary.json", summary.dump(2) + "\n");
    if (journal != nullptr && !config_.session.keep_journal) {  // the files hold all it held now
      std::error_code ec;
      std::filesystem::remove(journal->file(), ec);
    }
    if (products_) products_->enqueue(dir);  // made in the background; the next START does not wait
    log::info("session {}: stopped; {} poses, {} map points in {} tiles; files in {}", id, s.poses.load(), map.size(),
              map.tile_count(), dir.string());
    if (config_.imu.enabled) {
      const std::string problems =
          describe_problems(s.imu, imu_source_name(config_.imu.source));
      if (!problems.empty()) log::warn("session {}: {}", id, problems);
    }
  } catch (const std::exception& e) {
    // The trajectory is on disk already; say what is missing and carry on.
    log::error("session {}: writing its files failed: {}", id, e.what());
  }
  pipeline.reset();
  // The next session's pipeline, built now so that its START is quick.
  std::unique_ptr<Pipeline> next;
  try {
    next = build_pipeline();
  } catch (const std::exception& e) {
    log::error("the next session's pipeline cannot be built: {}", e.what());
  }
  {
    const std::lock_guard lock(mutex_);
    standby_ = std::move(next);
  }
  if (outputs_.ended) outputs_.ended(id);
  finishing_ = false;
}

bool Sessions::running() const {
  const std::lock_guard lock(mutex_);
  return pipeline_ != nullptr || finishing_;
}

std::string session_notes(const std::filesystem::path& dir) {
  std::string notes;
  if (std::ifstream summary(dir / "summary.json"); summary) {
    const nlohmann::json j = nlohmann::json::parse(summary, nullptr, false);
    if (j.is_object() && j.contains("recovered")) notes += " recovered";
  }
  // `adit join` placed it into another session's map (docs/SESSIONS.md, Joining sessions).
  if (std::ifstream joined(dir / "joined.json"); joined) {
    const nlohmann::json j = nlohmann::json::parse(joined, nullptr, false);
    if (j.is_object() && j.value("success", false) && j.contains("joined_to") && j["joined_to"].is_string())
      notes += " joined to " + j["joined_to"].get<std::string>();
  }
  return notes;
}

std::vector<std::string> Sessions::list() const {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(root_, ec))
    if (entry.is_directory()) out.push_back(entry.path().filename().string());
  std::sort(out.begin(), out.end());
  for (std::string& id : out) id += session_notes(root_ / id);
  return out;
}

std::filesystem::path Sessions::folder(const std::string& id) const { return root_ / id; }

std::string Sessions::hint(const protocol::LocaliseHint& hint) {
  const std::lock_guard lock(mutex_);
  if (!pipeline_ || finishing_) return "no session is mapping";
  PriorLocaliser* prior = pipeline_->prior_localiser();
  if (prior == nullptr) return "no prior map is configured (prior_map.dir)";
  return prior->set_hint(hint);
}

namespace {

// A session id from the network names a folder under the sessions' root only.
bool plain_session_name(const std::string& id) {
  return !id.empty() && id.size() <= 64 && id.front() != '.' &&
         std::all_of(id.begin(), id.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_'; });
}

}  // namespace

std::optional<MapFrame> Sessions::stored_frame(const std::string& id) const {
  if (!plain_session_name(id)) return std::nullopt;
  try {
    return stored_session_frame(folder(id));
  } catch (const std::exception& e) {
    log::warn("session {}: its tiles are sent in its own frame: {}", id, e.what());
    return std::nullopt;
  }
}

std::string Sessions::load_tiles(const std::string& id, TileStore& into) const {
  if (!plain_session_name(id)) return fmt::format("'{}' is not a session name", id);
  std::error_code ec;
  const std::filesystem::path graph = folder(id) / kGraphTilesFolder;
  const std::filesystem::path tiles = std::filesystem::is_directory(graph, ec) ? graph : folder(id) / "tiles";
  // A finished session that mapped nothing (stopped, or killed, before its
  // first map point) has no tiles: its map is empty, not missing.
  if (!std::filesystem::is_directory(tiles, ec))
    return std::filesystem::exists(folder(id) / "summary.json", ec) ? ""
                                                                    : fmt::format("no stored tiles for session '{}'", id);
  std::size_t bad = 0;
  std::string first_problem;
  for (const auto& entry : std::filesystem::directory_iterator(tiles, ec)) {
    if (entry.path().extension() != ".adt") continue;
    std::int64_t tile_id = 0;
    const std::string stem = entry.path().stem().string();
    const auto [end, err] = std::from_chars(stem.data(), stem.data() + stem.size(), tile_id);
    // Only the tile's segment table stays in RAM; its frames are read from the file when sent.
    const std::string problem = err != std::errc{} || end != stem.data() + stem.size()
                                    ? entry.path().string() + ": not named <tile id>.adt"
                                    : into.insert_file(tile_id, entry.path(), realtime_us());
    if (!problem.empty() && bad++ == 0) first_problem = problem;
  }
  if (bad > 0)
    log::warn("session {}: {} stored tile files are unreadable and were skipped (first: {})", id, bad, first_problem);
  return "";
}

// Every fault of the running session, most urgent first, joined by "; ":
// what is wrong now (silence, a full disk, a bus off) and what has happened
// with its count (packets lost, clock steps, IMU gaps), so that each one a
// crew should know of is in the status log. Called with mutex_ held.
std::string Sessions::session_faults(const PipelineStats& s, std::uint64_t datagrams, const std::string& imu_source,
                                     std::int64_t disk_free) {
  std::vector<std::string> faults;
  const auto add = [&faults](std::string fault) {
    if (!fault.empty()) faults.push_back(std::move(fault));
  };
  const std::int64_t last_packet_mono = s.last_packet_mono_ns.load();
  const double silent_s = 1e-9 * static_cast<double>(monotonic_ns() - last_packet_mono);
  // The recording stops before the disk is full, so the journal and the map files still fit.
  const double reserve = config_.session.record_min_free_mb * 1e6;
  if (disk_free >= 0 && static_cast<double>(disk_free) < reserve) pipeline_->stop_recording(RecordingStop::low_disk);
  const auto recording = static_cast<RecordingStop>(s.recording_stopped.load());
  const JournalWriter* journal = pipeline_->journal();
  if (pipeline_->drained()) add("the recording has ended");
  if (journal != nullptr) add(journal->fault());  // disk full
  if (recording != RecordingStop::recording)
    add(fmt::format("raw recording stopped: {}; the mapping goes on", to_string(recording)));
  if (last_packet_mono == 0) add("no LiDAR packets yet");
  else if (silent_s > 1.0 && !pipeline_->drained()) add(fmt::format("no LiDAR packets for {:.0f} s", silent_s));
  if (s.silences.load() > 0)
    add(fmt::format("LiDAR silent {} times (longest {:.1f} s)", s.silences.load(),
                    1e-9 * static_cast<double>(s.longest_silence_ns.load())));
  if (const CanFeedStats* can = pipeline_->can_stats()) {
    const auto bus = static_cast<drivers::can::BusState>(can->bus_state.load());
    if (bus != drivers::can::BusState::ok || can->bus_off.load() > 0)
      add(fmt::format("CAN bus {}: bus-off {}, recovered {}, {} error frames", drivers::can::bus_state_name(bus),
                      can->bus_off.load(), can->recoveries.load(), can->error_frames.load()));
  }
  if (s.dropped_packets.load() + s.dropped_scans.load() > 0)
    add(fmt::format("dropped {} packets, {} scans: a stage is too slow", s.dropped_packets.load(),
                    s.dropped_scans.load()));
  if (s.socket_drops.load() > 0)
    add(fmt::format("{} datagrams overflowed the socket's receive buffer: the receiver was held up (lidar.receive_buffer_bytes, CPU load)",
                    s.socket_drops.load()));
  if (s.missing_packets.load() + s.duplicate_packets.load() + s.late_packets.load() > 0)
    add(fmt::format("LiDAR link: {} packets missing ({:.1f} %), {} repeated, {} late (skipped)",
                    s.missing_packets.load(),
                    100.0 * static_cast<double>(s.missing_packets.load()) /
                        static_cast<double>(std::max<std::uint64_t>(1, datagrams + s.missing_packets.load())),
                    s.duplicate_packets.load(), s.late_packets.load()));
  if (s.clock_steps.load() > 0)
    add(fmt::format("host clock stepped {} times, last {:+.3f} s (stamps unaffected)", s.clock_steps.load(),
                    1e-9 * static_cast<double>(s.last_clock_step_ns.load())));
  const ImuStats& imu = s.imu;
  if (config_.imu.enabled && imu.samples.load() == 0 && s.scans.load() > 10)
    add(fmt::format("no IMU readings ({}) after {} scans", imu_source, s.scans.load()));
  else if (config_.imu.enabled)
    add(describe_problems(imu, imu_source));  // "" when the IMU has none
  std::string joined;
  for (const std::string& f : faults) joined += (joined.empty() ? "" : "; ") + f;
  return joined;
}

StatusSample Sessions::status_sample() {
  StatusSample sample;
  sample.utime = realtime_us();
  sample.disk_free_bytes = disk_free_bytes(std::filesystem::exists(root_) ? root_ : std::filesystem::path(config_.payload.state_dir));
  const std::lock_guard lock(mutex_);
  if (!pipeline_) {
    sample.fault = recovery_notice_;  // a session rebuilt after a crash, until the next one starts
    return sample;
  }
  const PipelineStats& s = pipeline_->stats();
  const std::int64_t now = monotonic_ns();
  const double dt = last_sample_ns_ == 0 ? 0.0 : 1e-9 * static_cast<double>(now - last_sample_ns_);
  const std::uint64_t datagrams = s.datagrams.load();
  SensorHealth lidar;
  lidar.name = "lidar " + config_.lidar.model;
  lidar.packet_rate_hz = dt > 0 ? static_cast<float>(static_cast<double>(datagrams - last_datagrams_) / dt) : 0.0F;
  lidar.packets_dropped =
      static_cast<std::int64_t>(s.dropped_packets.load() + s.bad_packets.load() + s.missing_packets.load());
  lidar.last_seen_utime = s.last_packet_realtime_ns.load() / 1000;
  lidar.time_offset_s = static_cast<float>(1e-9 * static_cast<double>(s.clock_offset_ns.load()));
  sample.sensors.push_back(lidar);
  // The IMU as one more sensor (sensor_health_t unchanged, so older clients
  // read it): its rate from its own stamps, its dropped and refused readings
  // (time going back, undecodable, unclocked), its configured clock offset;
  // its other problems (gaps, saturation, stuck axes) name themselves in the fault.
  const ImuStats& imu = s.imu;
  const std::string imu_source(imu_source_name(config_.imu.source));
  if (config_.imu.enabled) {
    SensorHealth h;
    h.name = "imu " + imu_source;
    h.packet_rate_hz = static_cast<float>(imu.rate_hz.load());
    h.packets_dropped = static_cast<std::int64_t>(imu.dropped.load() + imu.count(ImuProblem::time_back) +
                                                  imu.count(ImuProblem::undecodable) + imu.count(ImuProblem::unclocked));
    h.last_seen_utime = imu.last_seen_realtime_ns.load() / 1000;
    h.time_offset_s = static_cast<float>(imu.time_offset_s.load());
    sample.sensors.push_back(h);
  }
  const std::vector<StageLoad> loads = pipeline_->loads();
  last_cpu_s_.resize(loads.size(), 0.0);
  for (std::size_t i = 0; i < loads.size(); ++i) {
    const double load = dt > 0 ? (loads[i].cpu_s - last_cpu_s_[i]) / dt : 0.0;
    last_cpu_s_[i] = loads[i].cpu_s;
    sample.threads.push_back({loads[i].name, static_cast<float>(load), static_cast<std::int32_t>(loads[i].queue_depth),
                              static_cast<std::int32_t>(loads[i].queue_capacity)});
  }
  last_sample_ns_ = now;
  last_datagrams_ = datagrams;
  const LoopClosureStage* loops = pipeline_->loop_closure();
  const LoopClosureStage* moving = config_.map.loops_move_map ? loops : nullptr;
  sample.frame = session_frame(pipeline_->prior_localiser(), pipeline_->level(), moving, pipeline_->refinement());
  if (moving != nullptr) sample.graph = moving->live().latest();
  if (loops != nullptr) sample.loops = loop_status_of(s, loops->live().latest().get(), moving != nullptr);
  sample.fault = session_faults(s, datagrams, imu_source, sample.disk_free_bytes);
  return sample;
}

std::vector<const Heartbeat*> Sessions::heartbeats() const {
  const std::lock_guard lock(mutex_);
  return pipeline_ ? pipeline_->heartbeats() : std::vector<const Heartbeat*>{};
}

std::vector<std::string> Sessions::take_warnings() {
  const std::lock_guard lock(mutex_);
  return std::exchange(warnings_, {});
}

}  // namespace adit::daemon
