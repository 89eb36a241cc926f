// The pipeline: builds, wires, starts and joins the stages; no stage logic.
// (pipeline.hpp)
#include "adit/daemon/pipeline.hpp"

#include <mutex>
#include <optional>

#include "adit/common/clock.hpp"
#include "adit/common/log.hpp"
#include "adit/daemon/can_feed.hpp"
#include "adit/daemon/imu_pose_feed.hpp"
#include "adit/daemon/journal_writer.hpp"
#include "adit/daemon/lidar_source.hpp"
#include "adit/daemon/loop_closure_stage.hpp"
#include "adit/daemon/mapping_stage.hpp"
#include "adit/daemon/packet_imu.hpp"
#include "adit/daemon/prior_localiser.hpp"
#include "adit/daemon/odometry_stage.hpp"
#include "adit/daemon/output_stage.hpp"
#include "adit/daemon/scan_odometry.hpp"
#include "adit/daemon/thread_settings.hpp"
#include "adit/protocol/prior_input.hpp"
#include "adit/slam/prior_map_file.hpp"

namespace adit::daemon {
namespace {

// The CAN thread runs for the wheels, a CAN IMU, or both.
std::unique_ptr<CanFeed> can_feed_of(const config::Config& c, HostClock clock) {
  const bool imu = c.imu.enabled && c.imu.source == config::ImuSource::can;
  if (!c.can.enabled || (!c.wheel_odometry.enabled && !imu)) return nullptr;
  return std::make_unique<CanFeed>(c, clock);
}

// The IMU the odometry reads: the CAN feed's or the LiDAR's own (an Ouster's
// or a Livox's, LidarSource), or none.
ImuSource* imu_source_of(const config::Config& c, CanFeed* can, LidarSource& source) {
  if (!c.imu.enabled) return nullptr;
  if (c.imu.source != config::ImuSource::can) return source.imu();
  return can;
}

// One localisation try gathers this many scans (1 s of a 10 Hz LiDAR, as the
// benchmark's starts) and at most this many points in each of its two windows
// (at the map's resolution a VLP-16 scan has a few thousand).
constexpr int kPriorScansPerTry = 10;
constexpr std::size_t kPriorCloudPoints = 400'000;

// The prior (prior_map.dir, read again for this pipeline: a bad one was named
// at start in run.cpp; or a stored session's map prepared here: about half a
// second for a 90 s session's 680 k points) and its localiser; none when there
// is no prior or it is unusable (logged: the session maps without it).
std::unique_ptr<PriorLocaliser> prior_localiser_of(const config::Config& c, const PipelineOptions& o,
                                                   const std::atomic<bool>& stop, std::string& source) {
  const bool from_session = c.prior_map.dir.empty() && !o.prior_session_map.empty();
  source = from_session ? o.prior_session_map.string() : c.prior_map.dir;
  if (source.empty()) return nullptr;
  try {
    slam::PriorMap prior;
    if (from_session) {
      const protocol::PriorInput input = protocol::read_prior_input(o.prior_session_map);
      std::vector<Eigen::Vector3f> points(input.points.size());
      for (std::size_t i = 0; i < points.size(); ++i)
        points[i] = Eigen::Vector3f(input.points[i][0], input.points[i][1], input.points[i][2]);
      prior = slam::prepare_prior_map(points);
    } else {
      prior = slam::read_prior_map(c.prior_map.dir);
    }
    if (const std::string problem = slam::check_prior_map(prior); !problem.empty()) {
      log::error("prior map {}: not usable ({}); mapping without it", source, problem);
      source.clear();
      return nullptr;
    }
    if (from_session) log::info("prior map: the previous session's map {} ({} points kept)", source, prior.points.size());
    return std::make_unique<PriorLocaliser>(std::move(prior), kPriorScansPerTry, kPriorCloudPoints, stop,
                                            c.prior_map.confirm);
  } catch (const std::exception& e) {
    log::error("prior map {}: {}; mapping without it", source, e.what());
    source.clear();
    return nullptr;
  }
}

}  // namespace

struct Pipeline::Impl {
  Impl(const config::Config& c, const PipelineOptions& o)
      : config(c),
        source(c, o.replay_speed, o.odometry.max_scan_points, stats, stop, host_clock),
        odometry_config(odometry_config_of(c, o.odometry, source.max_points_per_scan())),
        can(can_feed_of(c, host_clock)),
        odometry(c, odometry_config, source.scans(), can.get(), imu_source_of(c, can.get(), source), o.mapping,
                 source.max_points_per_scan(), source.overflow(), stats, timings, stop),
        output(c, odometry.poses(), o.sinks.pose, stats, timings, stop),
        empty_map(slam::TiledMapConfig{}) {
    if (o.mapping) {
      mapping.emplace(c, odometry_config, *odometry.map_scans(), source.max_points_per_scan(), o.sinks.tile, stats, stop);
      mapping->publish_grid_to(o.sinks.grid);
      mapping->limit_tile_backlog(o.sinks.tile_backlog);
      mapping->time_grid_into(&timings.grid_ms);
    }
    if (mapping && c.map.loop_closure) {
      loops.emplace(c, stats, stop, slam::LoopClosureConfig{}, source.overflow() == Overflow::drop_oldest);
      mapping->feed_loops(&loops->input());
      // The live tiles follow the graph as the exported map does (docs/LOOPS.md, "Live tiles").
      if (c.map.loops_move_map) mapping->follow_graph(&loops->live());
    }
    open_files(o.trajectory_file, o.map_trajectory_file, o.record_file);
    if (ImuSource* imu = imu_source_of(c, can.get(), source); imu != nullptr && c.imu.pose_horizon_s > 0.0) {
      slam::ImuExtrapolatorConfig x;
      x.inertial = odometry_config.inertial;
      x.inertial.imu_position = imu->mounting().position_m;  // as the odometry's filter has it
      x.max_horizon_s = c.imu.pose_horizon_s;
      imu_poses.emplace(x, o.sinks.imu_pose);
      imu->feed_poses_to(&*imu_poses);
      odometry.anchor_imu_poses_in(&*imu_poses);
    }
    prior = prior_localiser_of(c, o, stop, prior_source);
    odometry.localise_against(prior.get());
  }

  void open_files(const std::filesystem::path& trajectory_file, const std::filesystem::path& map_trajectory_file,
                  const std::filesystem::path& record_file) {
    source.record_to(record_file);
    output.write_trajectory_to(trajectory_file);
    if (mapping) mapping->write_map_trajectory_to(map_trajectory_file);
  }

  std::vector<StageThread*> threads() {
    std::vector<StageThread*> out = source.threads();
    out.push_back(&odometry.thread());
    out.push_back(&output.thread());
    if (mapping) out.push_back(&mapping->thread());
    return out;  // not the loop-closure thread: a background thread is no watchdog matter
  }

  config::Config config;
  std::atomic<bool> stop{false};
  PipelineStats stats;
  PipelineTimings timings;
  const HostClock host_clock;  // the session's step-free timeline for live stamps (LiDAR and CAN alike)
  LidarSource source;
  slam::OdometryConfig odometry_config;
  std::unique_ptr<CanFeed> can;
  OdometryStage odometry;
  OutputStage output;
  std::optional<MappingStage> mapping;
  std::optional<LoopClosureStage> loops;
  std::optional<JournalWriter> journal;
  std::optional<ImuPoseFeed> imu_poses;  // the sources' threads read it: joined before it goes
  slam::TiledVoxelMap empty_map;  // map() without mapping
  std::vector<slam::Keyframe> no_keyframes;
  mutable std::mutex warnings_mutex;  // start() writes, the status reads: never per item
  std::vector<std::string> memory_warnings;
  std::atomic<bool> started{false};
  std::int64_t started_ns = 0;
  std::string prior_source;
  std::unique_ptr<PriorLocaliser> prior;  // last: its thread is joined before the rest goes
};

Pipeline::Pipeline(const config::Config& config, const PipelineOptions& options)
    : impl_(std::make_unique<Impl>(config, options)) {}

Pipeline::~Pipeline() {
  request_stop();
  join();
}

void Pipeline::start(const SessionFiles& files) {
  Impl& i = *impl_;
  if (i.started) throw std::logic_error("Pipeline::start called twice");
  i.open_files(files.trajectory_file, files.map_trajectory_file, files.record_file);
  if (i.mapping) i.mapping->spill_to(files.tiles_dir, files.keyframes_dir);
  if (i.mapping) i.mapping->write_level_to(files.level_frame_file);
  if (i.loops && !files.keyframes_dir.empty()) i.loops->spill_to(files.keyframes_dir / "loops");
  if (i.mapping && !files.journal_file.empty()) {
    i.journal.emplace(files.journal_file, i.config.session.journal_sync_s, i.stop);
    i.journal->start(files.journal_header);
    i.mapping->journal_to(&*i.journal);
  }
  if (i.can) i.can->start(files.can_record_file);
  if (i.config.threads.lock_memory) {
    std::vector<std::string> w = lock_memory();
    const std::lock_guard lock(i.warnings_mutex);
    i.memory_warnings = std::move(w);
  }
  i.started = true;
  i.started_ns = monotonic_ns();
  // Consumers first, so that each hand-off has its reader when its writer starts.
  if (i.loops) i.loops->start();
  if (i.mapping) i.mapping->start();
  i.output.start();
  if (i.prior) i.prior->start(files.prior_frame_file);
  i.odometry.start();
  i.source.start();
}

void Pipeline::request_stop() { impl_->stop.store(true, std::memory_order_release); }
void Pipeline::end_source() { impl_->source.end(); }
void Pipeline::stop_recording(RecordingStop why) {
  int recording = 0;
  impl_->stats.recording_stopped.compare_exchange_strong(recording, static_cast<int>(why), std::memory_order_relaxed);
}

void Pipeline::join() {
  Impl& i = *impl_;
  i.source.join();
  i.odometry.join();
  if (i.prior) i.prior->join();
  i.output.join();
  if (i.mapping) i.mapping->join();
  // Clean when the mapping ended by draining (a stop, the end of a replay), not by an abort.
  if (i.journal) i.journal->close(!i.stop.load(std::memory_order_acquire));
  if (i.loops) i.loops->finish();  // drains the keyframes the mapping left, then a last optimisation
  if (i.mapping) i.mapping->follow_final_correction();  // the live tiles where the map files will be
  if (i.can) i.can->stop();
  i.odometry.copy_imu_stats();  // the readings after the last scan too
  if (i.started) {
    i.timings.duration_s = 1e-9 * static_cast<double>(monotonic_ns() - i.started_ns);
    i.timings.sensor_span_s = 1e-9 * static_cast<double>(i.odometry.last_stamp_ns() - i.odometry.first_stamp_ns());
    i.started = false;
  }
}

bool Pipeline::drained() const {
  return impl_->output.thread().beat.finished.load(std::memory_order_acquire) &&
         (!impl_->mapping || impl_->mapping->thread().beat.finished.load(std::memory_order_acquire));
}

const PipelineStats& Pipeline::stats() const { return impl_->stats; }
const PipelineTimings& Pipeline::timings() const { return impl_->timings; }

std::vector<const Heartbeat*> Pipeline::heartbeats() const {
  std::vector<const Heartbeat*> beats;
  for (const StageThread* t : impl_->threads()) beats.push_back(&t->beat);
  if (impl_->can) beats.push_back(&impl_->can->heartbeat());
  return beats;
}

std::vector<StageLoad> Pipeline::loads() const {
  Impl& i = *impl_;
  std::vector<StageLoad> out;
  if (!i.started) return out;
  const std::vector<StageThread*> source = i.source.threads();
  out.push_back({source[0]->name(), source[0]->cpu_s(), 0, 0});
  out.push_back({source[1]->name(), source[1]->cpu_s(), i.source.packets_waiting(), i.source.packet_capacity()});
  const auto load = [](StageThread& thread, const auto& input) {
    return StageLoad{thread.name(), thread.cpu_s(), input.depth(), input.capacity()};
  };
  out.push_back(load(i.odometry.thread(), i.odometry.input()));
  out.push_back(load(i.output.thread(), i.output.input()));
  if (i.mapping) out.push_back(load(i.mapping->thread(), i.mapping->input()));
  return out;
}

std::optional<Eigen::Isometry3d> Pipeline::level() const {
  return impl_->mapping ? impl_->mapping->level() : std::nullopt;
}
Eigen::Isometry3d Pipeline::refinement() const {
  return impl_->mapping ? impl_->mapping->refinement() : Eigen::Isometry3d::Identity();
}
const slam::LiveGrid* Pipeline::grid() const { return impl_->mapping ? impl_->mapping->grid() : nullptr; }

const slam::TiledVoxelMap& Pipeline::map() const { return impl_->mapping ? impl_->mapping->map() : impl_->empty_map; }
const LoopClosureStage* Pipeline::loop_closure() const { return impl_->loops ? &*impl_->loops : nullptr; }
const JournalWriter* Pipeline::journal() const { return impl_->journal ? &*impl_->journal : nullptr; }
const CanFeedStats* Pipeline::can_stats() const { return impl_->can ? &impl_->can->stats() : nullptr; }
const ImuPoseFeed* Pipeline::imu_poses() const { return impl_->imu_poses ? &*impl_->imu_poses : nullptr; }
const PriorLocaliser* Pipeline::prior_localiser() const { return impl_->prior.get(); }
PriorLocaliser* Pipeline::prior_localiser() { return impl_->prior.get(); }
const std::string& Pipeline::prior_source() const { return impl_->prior_source; }
const TileSpill* Pipeline::tile_spill() const { return impl_->mapping ? impl_->mapping->tile_spill() : nullptr; }
const std::vector<slam::Keyframe>& Pipeline::keyframes() const {
  return impl_->mapping ? impl_->mapping->keyframes() : impl_->no_keyframes;
}

std::vector<std::string> Pipeline::warnings() const {
  std::vector<std::string> out;
  for (const StageThread* t : impl_->threads()) {
    const std::vector<std::string> w = t->warnings();
    out.insert(out.end(), w.begin(), w.end());
  }
  if (impl_->loops) {
    const std::vector<std::string> w = impl_->loops->thread().warnings();
    out.insert(out.end(), w.begin(), w.end());
  }
  const std::lock_guard lock(impl_->warnings_mutex);
  out.insert(out.end(), impl_->memory_warnings.begin(), impl_->memory_warnings.end());
  return out;
}

}  // namespace adit::daemon
