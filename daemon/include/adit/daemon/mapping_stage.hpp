#pragma once
// The pipeline's mapping stage: registered scans in, the session's map out.
//
// In:   each valid scan's body-frame points, times and intensities with its
//       odometry pose (MapSlot).
// Out:  the tiled voxel map and keyframes (read after join()); changed tiles
//       to the tile sink at most once per map.publish_period_s; the live
//       2D grid's changed patches to the grid sink at most once per
//       grid.publish_period_s; the map's
//       poses as TUM; tiles the sensor has left, crowded tiles and old
//       keyframes' scans to the session folder (bounded memory).
// A scan is mapped one scan late: deskewed with the corrected motion over its
// own sweep, pose_k⁻¹·pose_k+1 (odometry could only deskew with its
// prediction), optionally refined against the map (slam/map_refiner.hpp),
// then added. Thread "mapping": the map grows by nature and tile files are
// written here, so it may allocate and do file I/O; it never blocks another
// stage (live, its hand-off drops the oldest scan; a replay waits).

#include <atomic>
#include <cmath>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <vector>

#include "adit/config/config.hpp"
#include "adit/daemon/correction_board.hpp"
#include "adit/daemon/handoff.hpp"
#include "adit/daemon/journal_writer.hpp"
#include "adit/daemon/keyframe_queue.hpp"
#include "adit/daemon/pipeline_items.hpp"
#include "adit/daemon/pipeline_stats.hpp"
#include "adit/daemon/stage_thread.hpp"
#include "adit/daemon/tile_spill.hpp"
#include "adit/slam/deskew.hpp"
#include "adit/slam/keyframes.hpp"
#include "adit/slam/live_grid.hpp"
#include "adit/slam/lie.hpp"
#include "adit/slam/map_refiner.hpp"
#include "adit/slam/revisit_filter.hpp"
#include "adit/slam/tiled_map.hpp"
#include "adit/slam/tum.hpp"
#include "adit/slam/voxel_downsample.hpp"

namespace adit::daemon {

class MappingStage {
 public:
  // `odometry`: the range limits and the longest gap after which a pose says
  // nothing of the sweep before it; `max_points`: the most points per scan.
  MappingStage(const config::Config& config, const slam::OdometryConfig& odometry, Handoff<MapSlot>& scans,
               std::size_t max_points, PipelineSinks::TileSink sink, PipelineStats& stats,
               const std::atomic<bool>& stop);

  // Before start(): the map's poses as TUM (throws adit::InputError naming
  // the file); where evicted tiles and old keyframes' scans go (empty = RAM).
  void write_map_trajectory_to(const std::filesystem::path& file);
  void spill_to(const std::filesystem::path& tiles_dir, const std::filesystem::path& keyframes_dir);
  // Before start(): gravity's level (session_frame.hpp) is written to `file`
  // (a failure is logged) from the odometry's first up, again when it has
  // turned by kLevelTurnRad and kLevelPeriodS have passed, and at the end;
  // empty = kept in RAM only (level()).
  void write_level_to(const std::filesystem::path& file) { level_file_ = file; }
  static constexpr double kLevelTurnRad = 0.005 * M_PI / 180.0;  // 4 mm over 50 m
  static constexpr double kLevelPeriodS = 2.0;
  // Any thread: the level last kept (slam::level_from_up of the odometry's up); nullopt before.
  std::optional<Eigen::Isometry3d> level() const;
  // Any thread: M·O⁻¹ at the last scan mapped, its map pose M (refined,
  // slam::MapRefiner) against its odometry pose O; identity before one. The
  // tiles hold the scans at M, the poses are published at O: this places a
  // pose among the tiles (frame_t, map_frame.hpp).
  Eigen::Isometry3d refinement() const;
  // Before start(): each keyframe also goes to `loops` (the loop-closure stage's queue).
  void feed_loops(KeyframeQueue* loops) { loops_ = loops; }
  // Before start(): the tiles sent go placed by the loop closure's latest
  // correction (map.loops_move_map; docs/LOOPS.md "Live tiles"): each sample
  // moved by the correction at its scan's time, and a tile sent before a new
  // correction sent again when any of its points moves by more than
  // kTileMoveM (a few tiles each flush, at most kReplaceBudgetMs of it).
  // Each scan goes into the live grid placed by the latest correction too (at
  // its time: the newest keyframe's, held), so the grid goes on where the
  // tiles are; cells already in the grid stay where they were put. With
  // map.merge_revisits a point whose place an earlier pass mapped, by the
  // latest correction, is not added (slam/revisit_filter.hpp).
  void follow_graph(const CorrectionBoard* graph);
  static constexpr double kTileMoveM = 0.02;
  // A new correction places the live tiles only when it moves the sensor's
  // place by more than kPlacementMoveM, or kPlacementPeriodS of the session
  // after the last one they took, and at the end (decision 074).
  static constexpr double kPlacementMoveM = 0.05;
  static constexpr double kPlacementPeriodS = 30.0;
  static constexpr std::int64_t kReplaceBudgetMs = 20;
  // Before start(): how many points sent as tiles still wait for the tile
  // sink's consumer. Tiles moved by a correction are sent again only while
  // at most kTileBacklogPoints wait (the rest at a later flush), and the final
  // flush waits for them to drain before each (kFinalBacklogWaitMs in all,
  // then sends the rest): a correction that moved the whole 30-minute map
  // queued 38 whole tiles, 229 MB, for the LCM thread (decision 065).
  void limit_tile_backlog(std::function<std::uint64_t()> backlog) { tile_backlog_ = std::move(backlog); }
  static constexpr std::uint64_t kTileBacklogPoints = 1'000'000;  // 40 MB as protocol::MapPoint
  static constexpr std::int64_t kFinalBacklogWaitMs = 10'000;
  // Before start(): each mapped scan's pose, the points each tile confirms and
  // each keyframe also go to the session journal.
  void journal_to(JournalWriter* journal) { journal_ = journal; }
  // Before start(): the live grid's changed patches go to `sink`.
  void publish_grid_to(PipelineSinks::GridSink sink) { grid_sink_ = std::move(sink); }
  // Before start(): each scan's grid insertion time (ms) goes to `ms`, up to
  // kTimingCapacity scans; read it after join().
  void time_grid_into(std::vector<double>* ms) {
    grid_ms_ = ms;
    if (grid_ms_ != nullptr) grid_ms_->reserve(kTimingCapacity);
  }
  void start();
  void join() { thread_.join(); }
  // After join(), once the loop closure has posted its last correction (the
  // keyframes the mapping left, then the refinement): the tiles sent go again
  // where it moves them by more than kTileMoveM, so that what a client holds
  // at the end is the exported map. Nothing without follow_graph().
  void follow_final_correction() {
    if (graph_ != nullptr) flush_tiles(true);
  }

  StageThread& thread() { return thread_; }
  const Handoff<MapSlot>& input() const { return scans_; }
  // Complete after join().
  const slam::TiledVoxelMap& map() const { return map_; }
  const TileSpill* tile_spill() const { return spill_ ? &*spill_ : nullptr; }
  const std::vector<slam::Keyframe>& keyframes() const { return keyframes_; }
  // The live 2D grid (null when grid.enabled is false). Complete after join().
  const slam::LiveGrid* grid() const { return grid_ ? &*grid_ : nullptr; }

 private:
  void loop();
  void map_scan(const MapSlot& slot, const slam::Vector6d& velocity);
  void spill_keyframes();
  void compact_tiles(const std::vector<slam::TileCoord>& coords);
  void restore_tiles(const std::vector<slam::TileCoord>& coords);
  void evict_tiles(const std::vector<slam::TileCoord>& coords);
  void flush_tiles(bool final = false);
  bool placement_due(const slam::CorrectionTrack* latest) const;
  std::string whole_tile(const slam::TileCoord& coord, std::vector<slam::MapSample>& buffer,
                         std::span<const slam::MapSample>& samples) const;
  void send_tile(const slam::TileCoord& coord, std::size_t first, std::span<const slam::MapSample> samples);
  std::size_t unsent_from(const slam::TileCoord& coord, std::size_t stored, std::size_t total) const;
  void send_unsent(const slam::TileCoord& coord, std::size_t stored, std::span<const slam::MapSample> whole);
  void replace_moved_tiles(bool all);
  bool tile_backlog_full() const { return tile_backlog_ && tile_backlog_() > kTileBacklogPoints; }
  void flush_grid();
  void insert_into_grid(std::int64_t stamp_ns, const Eigen::Vector3f& origin);
  void drop_revisits(std::int64_t stamp_ns);
  void journal_new_points();
  void tile_file_error(const std::string& problem);
  void follow_level(const Eigen::Vector3d& up, std::int64_t stamp_ns);
  void keep_level();

  const config::MapSection config_;
  const config::GridSection grid_config_;
  const Eigen::Vector3f sensor_in_body_;  // the LiDAR's origin: where the grid's rays start
  const float min_range_m_;
  const float max_range_m_;
  const double max_scan_gap_s_;
  Handoff<MapSlot>& scans_;
  PipelineSinks::TileSink sink_;
  PipelineStats& stats_;
  StageThread thread_;
  slam::TiledVoxelMap map_;
  slam::TileEviction eviction_;
  std::optional<TileSpill> spill_;        // with a tiles folder and map.evict_after_keyframes
  std::filesystem::path keyframes_dir_;   // empty = keyframe scans stay in RAM
  std::filesystem::path level_file_;
  std::optional<Eigen::Vector3d> latest_up_;  // the odometry's, from the last slot that had one
  std::optional<Eigen::Vector3d> kept_up_;    // the one level_ was made from
  std::int64_t kept_up_ns_ = 0;
  bool level_off_ = false;  // keeping it failed: the session stays in the odometry frame
  // The level (kept a few times a session) and the refinement (every scan),
  // read by the status at 2 Hz.
  mutable std::mutex frame_mutex_;
  std::optional<Eigen::Isometry3d> level_;
  Eigen::Isometry3d refinement_ = Eigen::Isometry3d::Identity();
  std::size_t keyframes_in_ram_from_ = 0; // keyframes before this one had their scans written out
  std::uint64_t keyframe_bytes_ = 0;
  KeyframeQueue* loops_ = nullptr;
  const CorrectionBoard* graph_ = nullptr;
  std::shared_ptr<const slam::CorrectionTrack> placement_;  // the tiles sent now are placed by it (null: identity)
  std::uint64_t placement_version_ = 0;                     // counts placement_'s changes
  std::int64_t placement_stamp_ns_ = 0;                     // the newest scan's stamp when placement_ was taken
  std::int64_t newest_stamp_ns_ = 0;                        // the newest mapped scan's stamp ...
  Eigen::Vector3d newest_position_ = Eigen::Vector3d::Zero();  // ... and its position (map frame)
  // Each tile sent: how many of its points the sink took (its next update
  // sends only what it gained since) and, with graph_, the correction they
  // were placed by, kept at their times only (CorrectionTrack::slice_for): a
  // tile unmoved by later corrections does not hold a whole track of its time.
  struct SentTile {
    std::uint64_t version = 0;  // placement_version_ when sent
    slam::CorrectionTrack track;
    double newest_s = 0;  // the newest of its samples' times (with graph_)
    std::size_t points = 0;
  };
  std::map<slam::TileCoord, SentTile> sent_;
  std::deque<slam::TileCoord> recheck_;  // tiles to check against placement_
  JournalWriter* journal_ = nullptr;
  std::map<slam::TileCoord, std::size_t> journaled_;  // per resident tile: points of tile() already journaled
  slam::KeyframeSelector keyframe_selector_;
  std::vector<slam::Keyframe> keyframes_;
  slam::VoxelDownsampler keyframe_downsampler_;
  slam::Deskewer deskewer_;
  std::optional<slam::MapRefiner> refiner_;  // with map.refine
  std::optional<slam::LiveGrid> grid_;       // with grid.enabled
  PipelineSinks::GridSink grid_sink_;
  std::function<std::uint64_t()> tile_backlog_;
  std::vector<double>* grid_ms_ = nullptr;
  std::vector<std::int8_t> grid_cells_;      // one patch, for the sink
  std::vector<Eigen::Vector3f> grid_points_; // a scan placed by the graph's correction, for the grid
  std::optional<slam::RevisitFilter> revisits_;  // with follow_graph() and map.merge_revisits
  std::vector<Eigen::Vector3f> earlier_;     // a scan's points where an earlier pass put their place
  std::vector<std::uint8_t> held_;           // ... and whether the map holds that voxel
  slam::TumWriter map_trajectory_;
  // Per-scan buffers, reserved for the largest scan.
  std::vector<Eigen::Vector3f> points_;
  std::vector<float> times_;
  std::vector<float> intensities_;
  std::vector<Eigen::Vector3f> deskewed_;
  std::vector<Eigen::Vector3f> keyframe_points_;
  MapSlot pending_;  // the scan waiting for the next pose
  bool have_pending_ = false;
  slam::Vector6d velocity_ = slam::Vector6d::Zero();
};

}  // namespace adit::daemon
