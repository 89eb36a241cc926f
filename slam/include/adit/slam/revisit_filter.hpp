#pragma once
// Where an earlier pass mapped the place a point lies: a revisit's points that
// the map already holds are duplicates.
//
// The map is kept in the odometry's frame, each sample where its scan's pose
// put it, and follows the pose graph by the correction C(t) at the sample's
// time (correction_track.hpp). The odometry drifts, so on a route driven again
// a revisit lands in new voxels of that frame: every lap added the whole route
// again, beside the first by the drift (14.7 M points and a map growing with
// each lap on the 30-minute mine drive; decision 068). In the graph's frame a
// point p measured at t lies at C(t)·p. An earlier pass mapped that place from
// near keyframe k, and put what it saw there at C(t_k)⁻¹·C(t)·p in the
// odometry's frame, by the latest correction for both times: a point whose
// voxel, or one beside it, is there in the map is one the map has
// (TiledVoxelMap::holds; the caller drops it).
//
// k is a keyframe of the first pass through the place: of the first run of
// consecutive keyframes within radius_m of the point (in the graph's frame,
// at least min_age_s older than the scan), the nearest; chosen once per block
// of block_m (a wall seen from 30 m away is matched to the keyframe beside
// it, not to the sensor's). The first pass holds the place whole: later ones
// added only what it had not mapped (and what they alone added is not looked
// up, so a third pass may add that again). The first pass saw the place from
// anywhere within its range, not only from k: where the correction changes
// along the route, the placement is off by that change, and a point is kept
// as new. So duplicates are fewer, not none; nothing already mapped is moved,
// and a new thing within a voxel of a mapped surface is not added.
// Pure; the buffers grow to the largest scan and are reused.

#include <cstdint>
#include <memory>
#include <span>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

#include "adit/slam/correction_track.hpp"
#include "adit/slam/voxel_key.hpp"

namespace adit::slam {

struct RevisitConfig {
  double min_age_s = 30.0;  // an earlier pass's keyframe is at least this much older than the scan
  double radius_m = 10.0;   // and lies within this of the point, in the graph's frame
  float block_m = 2.0F;     // points are matched to keyframes by blocks of this edge
  // A point is held when the map has its voxel or one this many voxels
  // beside it along each axis (TiledVoxelMap::holds): range noise and the
  // correction's change along the route put a revisit's point a voxel off.
  int reach_voxels = 1;
};

class RevisitFilter {
 public:
  explicit RevisitFilter(const RevisitConfig& config = {}) : config_(config) {}

  // The loop closure's latest correction (null or empty: none, and no point
  // has an earlier pass).
  void follow(std::shared_ptr<const CorrectionTrack> track);
  const CorrectionTrack* track() const { return track_.get(); }
  const RevisitConfig& config() const { return config_; }

  // For each of `points` (the odometry's frame, measured at `stamp_ns`):
  // where the first pass put that place in the same frame, or NaN when no
  // keyframe old enough lies within radius_m.
  void place_in_earlier_pass(std::span<const Eigen::Vector3f> points, std::int64_t stamp_ns,
                             std::vector<Eigen::Vector3f>& earlier);

 private:
  std::int64_t first_pass_keyframe(const Eigen::Vector3f& graph_point, std::int64_t newest_ns) const;

  RevisitConfig config_;
  std::shared_ptr<const CorrectionTrack> track_;
  // The track's keyframes by their graph position, in radius_m cubes, oldest first.
  std::unordered_map<VoxelKey, std::vector<std::uint32_t>, VoxelKeyHash> cells_;
  // This scan's: per block of points its index in transforms_ (−1: no
  // earlier pass), per keyframe the same, and each keyframe's C(t_k)⁻¹·C(t).
  std::unordered_map<VoxelKey, std::int32_t, VoxelKeyHash> block_transform_;
  std::unordered_map<std::int64_t, std::int32_t> keyframe_transform_;
  std::vector<Eigen::Isometry3f> transforms_;
};

}  // namespace adit::slam
