// The mapping stage. In: valid scans with their odometry poses. Out: the
// tiled map and keyframes, changed tiles to the tile sink, the map's poses,
// tiles and keyframe scans on disk. Thread mapping; the one stage that
// allocates (the map grows) and writes files; never blocks another stage.
// (mapping_stage.hpp)
#include "adit/daemon/mapping_stage.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include <fmt/format.h>

#include "adit/common/clock.hpp"
#include "adit/common/log.hpp"
#include "adit/daemon/allocator.hpp"
#include "adit/daemon/extrinsics.hpp"
#include "adit/daemon/session_frame.hpp"
#include "adit/protocol/map_export.hpp"
#include "adit/slam/levelling.hpp"

namespace adit::daemon {
namespace {

constexpr std::size_t kKeyframeScansInRam = 100;  // the newest keyframes keep their scans in RAM (~5 MB)

slam::TiledMapConfig map_config_of(const config::MapSection& m) {
  return {static_cast<float>(m.tile_size_m), static_cast<float>(m.voxel_m), static_cast<std::uint8_t>(m.min_hits)};
}

slam::LiveGridConfig grid_config_of(const config::GridSection& g) {
  slam::LiveGridConfig c;
  c.resolution_m = static_cast<float>(g.resolution_m);
  c.band_below_m = static_cast<float>(g.band_below_m);
  c.band_above_m = static_cast<float>(g.band_above_m);
  c.tilt_tolerance_deg = static_cast<float>(g.tilt_tolerance_deg);
  c.max_range_m = static_cast<float>(g.max_range_m);
  c.patch_cells = g.patch_cells;
  return c;
}

// No point of a scan lies farther than max_range_m from the body (map_scan
// filters them), deskewing moves points by at most a sweep's motion, and the
// sensor's offset from the body is small: the margin covers both.
slam::TileEvictionConfig eviction_config_of(const config::MapSection& m) {
  return {static_cast<float>(m.max_range_m + m.evict_margin_m), m.evict_after_keyframes,
          static_cast<std::size_t>(m.compact_tile_voxels), static_cast<std::size_t>(m.resident_tiles_mb * 1e6)};
}

}  // namespace

MappingStage::MappingStage(const config::Config& config, const slam::OdometryConfig& odometry, Handoff<MapSlot>& scans,
                           std::size_t max_points, PipelineSinks::TileSink sink, PipelineStats& stats,
                           const std::atomic<bool>& stop)
    : config_(config.map),
      grid_config_(config.grid),
      sensor_in_body_(isometry_of(config.lidar.extrinsics).translation().cast<float>()),
      min_range_m_(odometry.min_range_m),
      max_range_m_(std::min(odometry.max_range_m, static_cast<float>(config.map.max_range_m))),
      max_scan_gap_s_(odometry.max_scan_gap_s),
      scans_(scans),
      sink_(std::move(sink)),
      stats_(stats),
      thread_("mapping", config.threads.mapping, stop),
      map_(map_config_of(config.map)),
      eviction_(eviction_config_of(config.map)),
      keyframe_selector_({config.map.keyframe_distance_m, config.map.keyframe_angle_deg}),
      keyframe_downsampler_(max_points) {
  if (config.map.refine) {
    slam::MapRefinerConfig refine;
    refine.max_scan_points = max_points;
    refiner_.emplace(refine);
  }
  if (config.grid.enabled) {
    grid_.emplace(grid_config_of(config.grid));
    grid_cells_.resize(static_cast<std::size_t>(config.grid.patch_cells) * static_cast<std::size_t>(config.grid.patch_cells));
    grid_points_.reserve(max_points);
  }
  for (std::vector<Eigen::Vector3f>* v : {&points_, &deskewed_, &keyframe_points_, &pending_.points}) v->reserve(max_points);
  for (std::vector<float>* v : {&times_, &intensities_, &pending_.times_s, &pending_.intensities}) v->reserve(max_points);
  pending_.sweep.reserve(slam::Odometry::kSweepMotionCapacity);
}

void MappingStage::write_map_trajectory_to(const std::filesystem::path& file) {
  if (!file.empty()) map_trajectory_ = slam::TumWriter(file);
}

void MappingStage::spill_to(const std::filesystem::path& tiles_dir, const std::filesystem::path& keyframes_dir) {
  if (config_.evict_after_keyframes == 0) return;
  if (!tiles_dir.empty()) spill_.emplace(tiles_dir, stored_tile_params(config_.tile_size_m));
  keyframes_dir_ = keyframes_dir;
}

std::optional<Eigen::Isometry3d> MappingStage::level() const {
  const std::lock_guard lock(frame_mutex_);
  return level_;
}

Eigen::Isometry3d MappingStage::refinement() const {
  const std::lock_guard lock(frame_mutex_);
  return refinement_;
}

void MappingStage::follow_level(const Eigen::Vector3d& up, std::int64_t stamp_ns) {
  if (level_off_) return;
  latest_up_ = up;
  if (kept_up_ && (1e-9 * static_cast<double>(stamp_ns - kept_up_ns_) < kLevelPeriodS ||
                   std::acos(std::clamp(up.normalized().dot(kept_up_->normalized()), -1.0, 1.0)) < kLevelTurnRad))
    return;
  kept_up_ns_ = stamp_ns;
  keep_level();
}

// latest_up_'s level into level_ and level_file_ (durably: a recovery after
// a crash levels the map by it). A failure is logged and ends the levelling.
void MappingStage::keep_level() {
  kept_up_ = latest_up_;
  try {
    const Eigen::Isometry3d level = slam::level_from_up(*latest_up_);
    {
      const std::lock_guard lock(frame_mutex_);
      level_ = level;
    }
    if (!level_file_.empty()) write_level_frame(level_file_, level);
  } catch (const std::exception& e) {
    log::warn("mapping: gravity's level not kept ({}); the exports stay in the odometry frame", e.what());
    level_off_ = true;
    std::error_code ignored;  // the exports stay unlevelled, as the recovery's would
    if (!level_file_.empty()) std::filesystem::remove(level_file_, ignored);
    const std::lock_guard lock(frame_mutex_);
    level_.reset();
  }
}

void MappingStage::start() {
  thread_.start([this] { loop(); });
}

void MappingStage::loop() {
  const auto period_ns = static_cast<std::int64_t>(config_.publish_period_s * 1e9);
  const auto grid_period_ns = static_cast<std::int64_t>(grid_config_.publish_period_s * 1e9);
  std::int64_t last_flush_ns = monotonic_ns();
  std::int64_t last_grid_ns = last_flush_ns;
  while (!thread_.stopping()) {
    if (monotonic_ns() - last_flush_ns >= period_ns) {
      flush_tiles();
      last_flush_ns = monotonic_ns();
    }
    if (monotonic_ns() - last_grid_ns >= grid_period_ns) {
      flush_grid();
      last_grid_ns = monotonic_ns();
    }
    // Waits for a scan until the next flush (tiles or grid) is due.
    MapSlot* slot = scans_.take_or_wait([&] {
      const std::int64_t now = monotonic_ns();
      return thread_.idle() && now - last_flush_ns < period_ns && now - last_grid_ns < grid_period_ns;
    });
    if (slot == nullptr) {
      if (scans_.drained()) break;
      continue;
    }
    thread_.beat.beat();
    if (have_pending_) {
      const double dt = 1e-9 * static_cast<double>(slot->stamp_ns - pending_.stamp_ns);
      // After a gap the next pose says nothing of this sweep: keep the last motion.
      if (dt > 0.0 && dt <= max_scan_gap_s_) velocity_ = slam::log_se3(pending_.pose.inverse() * slot->pose) / dt;
      map_scan(pending_, velocity_);
    }
    // The slot's buffers and the pending ones have the same capacity: swap, no copy.
    std::swap(pending_, *slot);
    have_pending_ = true;
    scans_.release(slot);
  }
  if (have_pending_ && !thread_.stopping()) map_scan(pending_, velocity_);  // the last sweep: the last motion known
  have_pending_ = false;
  if (latest_up_ && !level_off_ && (!kept_up_ || *kept_up_ != *latest_up_)) keep_level();  // the last up for the exports
  flush_tiles(true);
  flush_grid();
  map_trajectory_.flush();
  stats_.map_bytes.store(map_.memory_bytes(), std::memory_order_relaxed);
  stats_.dropped_map_scans.store(scans_.dropped());
}

void MappingStage::map_scan(const MapSlot& slot, const slam::Vector6d& velocity) {
  if (slot.up) follow_level(*slot.up, slot.stamp_ns);
  points_.clear();
  times_.clear();
  intensities_.clear();
  const float min2 = min_range_m_ * min_range_m_;
  const float max2 = max_range_m_ * max_range_m_;
  const bool timed = slot.times_s.size() == slot.points.size();
  for (std::size_t i = 0; i < slot.points.size(); ++i) {
    const float r2 = slot.points[i].squaredNorm();
    if (!std::isfinite(r2) || r2 < min2 || r2 > max2) continue;
    points_.push_back(slot.points[i]);
    times_.push_back(timed ? slot.times_s[i] : 0.0F);
    intensities_.push_back(i < slot.intensities.size() ? slot.intensities[i] : 0.0F);
  }
  deskewed_.resize(points_.size());
  // An inertial scan as the odometry deskewed it (the IMU's motion through the
  // sweep); otherwise with the motion between its pose and the next: in a
  // fast, changing turn the constant velocity left a drone's keyframes turned
  // by 1.5° (docs/decisions/055).
  if (!slot.sweep.empty())
    deskewer_.deskew(points_, times_, slot.sweep, deskewed_);
  else
    deskewer_.deskew(points_, times_, velocity, deskewed_);
  // The map's pose of the scan: the odometry's, refined against the map of
  // the scans before it (slam::MapRefiner says why). Once the odometry is
  // anchored to a prior map it registers against the prior as well, and its
  // pose is taken as it is: refined against the scans mapped before the
  // anchor, the map would keep their error (decision 073).
  const bool refine = refiner_ && !slot.anchored;
  const Eigen::Isometry3d map_pose = refine ? refiner_->refine(slot.pose, deskewed_, slot.inertial) : slot.pose;
  map_trajectory_.write(slot.stamp_ns, map_pose);
  newest_stamp_ns_ = slot.stamp_ns;
  newest_position_ = map_pose.translation();
  if (refiner_) {
    const std::lock_guard lock(frame_mutex_);
    refinement_ = map_pose * slot.pose.inverse();  // identity once anchored
  }
  if (journal_ != nullptr) journal_->map_pose(slot.stamp_ns, map_pose);
  const bool keyframe = keyframe_selector_.take(map_pose);
  if (keyframe) {
    keyframe_downsampler_.downsample(deskewed_, static_cast<float>(config_.keyframe_voxel_m), keyframe_points_);
    keyframes_.push_back({slot.stamp_ns, map_pose, keyframe_points_});
    if (loops_ != nullptr)
      loops_->push({slot.stamp_ns, map_pose, keyframe_points_, slot.anchored}, [this] { return thread_.idle(); });
    if (journal_ != nullptr) journal_->keyframe(slot.stamp_ns, map_pose, keyframe_points_);
    keyframe_bytes_ += sizeof(slam::Keyframe) + keyframes_.back().points.capacity() * sizeof(Eigen::Vector3f);
    stats_.keyframes.store(keyframes_.size(), std::memory_order_relaxed);
    stats_.keyframe_bytes.store(keyframe_bytes_, std::memory_order_relaxed);
  }
  const Eigen::Isometry3f pose = map_pose.cast<float>();
  for (Eigen::Vector3f& p : deskewed_) p = pose * p;
  if (grid_) {
    const std::int64_t grid_start_ns = monotonic_ns();
    insert_into_grid(slot.stamp_ns, pose * sensor_in_body_);
    if (grid_ms_ != nullptr && grid_ms_->size() < kTimingCapacity)
      grid_ms_->push_back(1e-6 * static_cast<double>(monotonic_ns() - grid_start_ns));
  }
  if (revisits_) drop_revisits(slot.stamp_ns);
  if (spill_) restore_tiles(map_.evicted_hit_by(deskewed_));
  map_.add(deskewed_, intensities_, 1e-9 * static_cast<double>(slot.stamp_ns));
  journal_new_points();  // before eviction: an evicted tile's points are all in the journal
  if (keyframe) {
    const std::uint64_t bytes = map_.memory_bytes();  // a walk over the tiles
    if (bytes > stats_.map_bytes_peak.load(std::memory_order_relaxed))
      stats_.map_bytes_peak.store(bytes, std::memory_order_relaxed);
  }
  if (spill_ && keyframe) {
    const std::vector<slam::TileCoord> cold = eviction_.cold_tiles(map_, map_pose.translation().cast<float>());
    evict_tiles(cold);
    // After the eviction: a tile both cold and crowded leaves RAM, and is not read back to be compacted.
    const std::vector<slam::TileCoord> crowded = eviction_.crowded_tiles(map_);
    compact_tiles(crowded);
    // The freed tiles lie amid the mapping thread's arena (allocator.hpp).
    if (!cold.empty() || !crowded.empty()) return_free_pages();
  }
  if (!keyframes_dir_.empty() && keyframe) spill_keyframes();
  stats_.mapped_scans.fetch_add(1, std::memory_order_relaxed);
  stats_.map_points.store(map_.size(), std::memory_order_relaxed);
  stats_.map_tiles.store(map_.tile_count(), std::memory_order_relaxed);
  stats_.resident_tiles.store(map_.resident_tile_count(), std::memory_order_relaxed);
  stats_.dropped_in_evicted.store(map_.dropped_in_evicted(), std::memory_order_relaxed);
  if (keyframe) stats_.map_bytes.store(map_.memory_bytes(), std::memory_order_relaxed);  // a walk over the tiles
}

// The scan (deskewed_, map frame) into the live grid: placed by the loop
// closure's latest correction when following the graph, as its tiles are.
void MappingStage::insert_into_grid(std::int64_t stamp_ns, const Eigen::Vector3f& origin) {
  const std::shared_ptr<const slam::CorrectionTrack> correction = graph_ != nullptr ? graph_->latest() : nullptr;
  if (correction == nullptr || correction->empty()) {
    grid_->insert(origin, deskewed_);
    return;
  }
  const Eigen::Isometry3f c = correction->at(stamp_ns).cast<float>();
  grid_points_.clear();
  for (const Eigen::Vector3f& p : deskewed_) grid_points_.push_back(c * p);
  grid_->insert(c * origin, grid_points_);
}

void MappingStage::follow_graph(const CorrectionBoard* graph) {
  graph_ = graph;
  if (graph_ != nullptr && config_.merge_revisits) revisits_.emplace();
}

// The scan's points (deskewed_, map frame) whose place an earlier pass mapped
// become NaN, which add() skips: placed by the latest correction where that
// pass put the place, their voxel is in the map (tiles evicted there read
// back first, as for the scan's own).
void MappingStage::drop_revisits(std::int64_t stamp_ns) {
  std::shared_ptr<const slam::CorrectionTrack> correction = graph_->latest();
  if (correction.get() != revisits_->track()) revisits_->follow(std::move(correction));
  revisits_->place_in_earlier_pass(deskewed_, stamp_ns, earlier_);
  if (spill_) restore_tiles(map_.evicted_hit_by(earlier_));
  map_.holds(earlier_, held_, revisits_->config().reach_voxels);
  std::uint64_t dropped = 0;
  for (std::size_t i = 0; i < deskewed_.size(); ++i) {
    if (held_[i] == 0) continue;
    deskewed_[i] = Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
    ++dropped;
  }
  stats_.revisit_points.fetch_add(dropped, std::memory_order_relaxed);
}

// The points each resident tile confirmed since its last journal record.
// tile() only grows until the tile is evicted (evict_tiles, compact_tiles
// forget its count; a restored tile's tile() starts empty again).
void MappingStage::journal_new_points() {
  if (journal_ == nullptr) return;
  for (const slam::TileCoord& coord : map_.tile_coords()) {
    const std::span<const slam::MapSample> points = map_.tile(coord);
    std::size_t& done = journaled_[coord];
    if (points.size() > done) journal_->tile_points(coord, points.subspan(done));
    done = points.size();
  }
}

// The first file error is logged; every one is counted. What could not be
// written stays in RAM; what could not be read is skipped.
void MappingStage::tile_file_error(const std::string& problem) {
  if (stats_.tile_file_errors.fetch_add(1, std::memory_order_relaxed) == 0) log::error("mapping: {}", problem);
}

// The scans of all but the newest kKeyframeScansInRam keyframes go to the
// session folder; their poses stay. Loop closure will read them back. A
// 30-minute drive keeps ~1800 keyframes of ~50 kB each; a radius rule would
// not bound them on a route that keeps coming back to the same drifts.
void MappingStage::spill_keyframes() {
  for (; keyframes_in_ram_from_ + kKeyframeScansInRam < keyframes_.size(); ++keyframes_in_ram_from_) {
    slam::Keyframe& k = keyframes_[keyframes_in_ram_from_];
    std::vector<protocol::MapPoint> points;
    points.reserve(k.points.size());
    for (const Eigen::Vector3f& p : k.points) points.push_back({p.x(), p.y(), p.z(), 0.0F, 0.0});
    try {
      std::filesystem::create_directories(keyframes_dir_);
      protocol::write_map(keyframes_dir_ / fmt::format("{}.ply", k.stamp_ns), protocol::MapFormat::ply, points);
    } catch (const std::exception& e) {  // kept in RAM then
      tile_file_error(e.what());
      continue;
    }
    keyframe_bytes_ -= k.points.capacity() * sizeof(Eigen::Vector3f);
    std::vector<Eigen::Vector3f>().swap(k.points);
    stats_.spilled_keyframes.fetch_add(1, std::memory_order_relaxed);
  }
  stats_.keyframe_bytes.store(keyframe_bytes_, std::memory_order_relaxed);
}

// The whole tiles these functions read back or write (compact, evict,
// restore, flush) live in a buffer local to each call, freed on return: a
// buffer kept as a member held the capacity of the largest tile of the
// session (24 B a point), resident between uses, and grew with the map.
//
// A tile holding too many voxels in RAM is written out, evicted and restored
// at once: its points go to its file and only a bit per voxel stays
// (unconfirmed voxels are lost, as on eviction).
void MappingStage::compact_tiles(const std::vector<slam::TileCoord>& coords) {
  std::vector<slam::MapSample> tile_buffer;
  for (const slam::TileCoord& coord : coords) {
    std::string problem = spill_->whole_tile(map_, coord, tile_buffer);
    if (problem.empty()) problem = spill_->write(coord, tile_buffer);
    if (!problem.empty()) {
      tile_file_error(problem);
      continue;
    }
    const std::size_t stored = map_.stored_points(coord);
    if (map_.evict(coord).changed && sink_) send_unsent(coord, stored, tile_buffer);
    journaled_.erase(coord);
    map_.restore(coord, tile_buffer);
    stats_.compacted_tiles.fetch_add(1, std::memory_order_relaxed);
  }
  stats_.lost_candidates.store(map_.lost_candidates(), std::memory_order_relaxed);
}

// The sensor has come back to tiles it had left; they are read back, so the
// scan continues them instead of starting copies. A tile that cannot be read
// stays evicted (its file intact) and add() skips the points that fall into it.
void MappingStage::restore_tiles(const std::vector<slam::TileCoord>& coords) {
  std::vector<slam::MapSample> tile_buffer;
  for (const slam::TileCoord& coord : coords) {
    if (const std::string problem = spill_->read(coord, tile_buffer); !problem.empty()) {
      tile_file_error(problem);
      continue;
    }
    map_.restore(coord, tile_buffer);
    stats_.restored_tiles.fetch_add(1, std::memory_order_relaxed);
  }
}

// Tiles the sensor has left go to the session's tiles/ folder and leave RAM.
// A tile whose last change was not published yet goes to the sink first. A
// restored tile's file holds its stored part: it is rewritten with the new
// points appended, or left as it is when nothing is new.
void MappingStage::evict_tiles(const std::vector<slam::TileCoord>& coords) {
  std::vector<slam::MapSample> tile_buffer;
  for (const slam::TileCoord& coord : coords) {
    const std::size_t stored = map_.stored_points(coord);
    const bool fresh = stored == 0 || !map_.tile(coord).empty();
    if (fresh) {
      std::string problem = spill_->whole_tile(map_, coord, tile_buffer);
      if (problem.empty()) problem = spill_->write(coord, tile_buffer);
      if (!problem.empty()) {
        tile_file_error(problem);
        continue;
      }
    }
    if (map_.evict(coord).changed && sink_) {
      if (fresh) send_unsent(coord, stored, tile_buffer);
      else if (spill_->whole_tile(map_, coord, tile_buffer).empty()) send_tile(coord, 0, tile_buffer);
    }
    journaled_.erase(coord);
    stats_.evicted_tiles.fetch_add(1, std::memory_order_relaxed);
  }
  stats_.lost_candidates.store(map_.lost_candidates(), std::memory_order_relaxed);
}

// The whole content of a tile: what the map holds, or with a stored part
// (compacted or evicted) read back into `buffer`: its stored part and what is
// new, decoding it costs a few ms per changed tile and period; "" or why not.
std::string MappingStage::whole_tile(const slam::TileCoord& coord, std::vector<slam::MapSample>& buffer,
                                     std::span<const slam::MapSample>& samples) const {
  if (!spill_ || (map_.stored_points(coord) == 0 && !map_.is_evicted(coord))) {
    samples = map_.tile(coord);
    return {};
  }
  std::string problem = spill_->whole_tile(map_, coord, buffer);
  samples = buffer;
  return problem;
}

// A tile's points from `first` on (`samples`; 0: the whole tile) to the
// sink, placed by the graph's correction when following it (each sample by
// the correction at its scan's time).
void MappingStage::send_tile(const slam::TileCoord& coord, std::size_t first, std::span<const slam::MapSample> samples) {
  SentTile& sent = sent_[coord];
  if (graph_ != nullptr) {
    slam::CorrectionTrack slice = placement_ ? placement_->slice_for(samples) : slam::CorrectionTrack{};
    sent.track = first > 0 ? sent.track.merged_with(slice) : std::move(slice);
    double newest = first > 0 ? sent.newest_s : -std::numeric_limits<double>::infinity();
    for (const slam::MapSample& s : samples) newest = std::max(newest, s.time_s);
    sent.newest_s = newest;
  }
  sent.version = placement_version_;
  bool taken = false;
  if (placement_ == nullptr) {
    taken = sink_(coord, first, samples);
  } else {
    std::vector<slam::MapSample> placed;
    slam::correct_samples(samples, placement_.get(), Eigen::Isometry3d::Identity(), placed);
    taken = sink_(coord, first, placed);
  }
  sent.points = taken ? first + samples.size() : 0;  // not taken: the next update goes whole
}

// Where an update of a tile holding `total` points, the first `stored` of
// them read back from its file, starts: after the points last sent, when
// they were placed as tiles are now and the tile has kept them in the order
// sent (all of its stored part, and what it holds in RAM has only grown);
// else 0, the whole tile (decision 074).
std::size_t MappingStage::unsent_from(const slam::TileCoord& coord, std::size_t stored, std::size_t total) const {
  const auto sent = sent_.find(coord);
  if (sent == sent_.end() || sent->second.version != placement_version_) return 0;
  const std::size_t n = sent->second.points;
  return n >= stored && n <= total ? n : 0;
}

// Of a tile's whole content (`whole`: its `stored` part, then what the map
// holds in RAM), what was not sent yet.
void MappingStage::send_unsent(const slam::TileCoord& coord, std::size_t stored,
                               std::span<const slam::MapSample> whole) {
  const std::size_t first = unsent_from(coord, stored, whole.size());
  send_tile(coord, first, whole.subspan(first));
}

// Whether the live tiles take the graph's newest correction `latest` now: the
// first one; once kPlacementPeriodS of the session has passed since the
// tiles took one; or when it moves where the sensor is by more than
// kPlacementMoveM (the pose a client draws with the latest correction would
// stand that far off the tiles). Each time they take one, every tile that
// changed goes whole and every tile sent is checked (decision 074).
bool MappingStage::placement_due(const slam::CorrectionTrack* latest) const {
  if (placement_ == nullptr || latest == nullptr) return true;
  if (1e-9 * static_cast<double>(newest_stamp_ns_ - placement_stamp_ns_) >= kPlacementPeriodS) return true;
  const Eigen::Isometry3d now = latest->at(newest_stamp_ns_);
  const Eigen::Isometry3d before = placement_->at(newest_stamp_ns_);
  return (now * newest_position_ - before * newest_position_).norm() > kPlacementMoveM;
}

void MappingStage::flush_tiles(bool final) {
  const std::vector<slam::TileCoord> changed = map_.take_changed();
  if (!sink_) return;
  if (graph_ != nullptr) {
    std::shared_ptr<const slam::CorrectionTrack> latest = graph_->latest();
    if (latest != placement_ && (final || placement_due(latest.get()))) {  // every tile sent is checked against it
      placement_ = std::move(latest);
      placement_stamp_ns_ = newest_stamp_ns_;
      ++placement_version_;
      recheck_.clear();
      for (const auto& [coord, sent] : sent_) recheck_.push_back(coord);
    }
  }
  std::vector<slam::MapSample> tile_buffer;
  std::span<const slam::MapSample> samples;
  for (const slam::TileCoord& coord : changed) {
    // What the tile gained, from RAM; the whole tile (its file read back)
    // only when it was not sent placed as now.
    const std::span<const slam::MapSample> held = map_.tile(coord);
    const std::size_t stored = map_.stored_points(coord);
    if (const std::size_t first = unsent_from(coord, stored, stored + held.size()); first >= stored)
      send_tile(coord, first, held.subspan(first - stored));
    else if (const std::string problem = whole_tile(coord, tile_buffer, samples); problem.empty())
      send_tile(coord, 0, samples);
    else
      tile_file_error(problem);
  }
  replace_moved_tiles(final);
}

// Tiles sent placed by an earlier correction go again when the latest moves
// any of their points by more than kTileMoveM; at most kReplaceBudgetMs of
// the mapping thread per flush and while the tile sink's backlog is short
// (all at the session's end), so a closure on a long session's map neither
// holds the scans back nor queues the whole map for the LCM thread.
void MappingStage::replace_moved_tiles(bool all) {
  const std::int64_t deadline = monotonic_ns() + kReplaceBudgetMs * 1'000'000;
  const std::int64_t wait_until = monotonic_ns() + kFinalBacklogWaitMs * 1'000'000;
  std::vector<slam::MapSample> tile_buffer;
  std::span<const slam::MapSample> samples;
  while (!recheck_.empty()) {
    if (!all && (monotonic_ns() >= deadline || tile_backlog_full())) break;
    // The final flush sends every moved tile, each once the backlog has drained.
    while (all && tile_backlog_full() && monotonic_ns() < wait_until) {
      thread_.beat.beat();
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    const slam::TileCoord coord = recheck_.front();
    recheck_.pop_front();
    const auto sent = sent_.find(coord);
    if (sent == sent_.end() || sent->second.version == placement_version_) continue;  // sent since, by the latest
    // Most checks find nothing moved: the tile's corners tell without reading its points (decision 074).
    const Eigen::Vector3d lo = Eigen::Vector3d(coord.x, coord.y, coord.z) * map_.config().tile_size_m;
    const Eigen::AlignedBox3d box(lo, lo + Eigen::Vector3d::Constant(map_.config().tile_size_m));
    if (!slam::correction_may_move(sent->second.track, placement_.get(), box, sent->second.newest_s, kTileMoveM)) {
      stats_.tiles_checked_for_loops.fetch_add(1, std::memory_order_relaxed);
      stats_.tiles_checked_by_corners.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    if (const std::string problem = whole_tile(coord, tile_buffer, samples); !problem.empty()) {
      tile_file_error(problem);
      continue;
    }
    stats_.tiles_checked_for_loops.fetch_add(1, std::memory_order_relaxed);
    if (!slam::correction_moves(samples, &sent->second.track, placement_.get(), kTileMoveM)) continue;
    send_tile(coord, 0, samples);
    stats_.tiles_moved_by_loops.fetch_add(1, std::memory_order_relaxed);
    stats_.points_moved_by_loops.fetch_add(samples.size(), std::memory_order_relaxed);
  }
}

// The live grid's patches whose cells changed since the last flush.
void MappingStage::flush_grid() {
  if (!grid_) return;
  const std::vector<slam::GridPatchCoord> changed = grid_->take_changed();
  stats_.grid_patches.store(grid_->patch_count(), std::memory_order_relaxed);
  if (!grid_sink_) return;
  for (const slam::GridPatchCoord& c : changed) {
    grid_->read(c, grid_cells_);
    grid_sink_(c, grid_->version(c), grid_cells_, grid_->patch_count());
  }
}

}  // namespace adit::daemon
