#pragma once
// Moving objects out of the map: a map point that later (or earlier) scans
// see through was not there all the time (a person, a vehicle). Each scan is
// kept as a range image in the sensor's own frame (rows: the rings by
// elevation, columns: azimuth bins), the visibility test of Removert (Kim &
// Kim, IROS 2020) and Dynablox's "seen free" (Schmid et al., RA-L 2023), done
// from the map point's side: the point is projected into the scan with the
// sensor's pose at the time its azimuth was fired, and the four returns that
// bracket its direction (the rings above and below, the azimuth bins either
// side) are looked at. The scan sees through the point when all four went
// farther than the point by a margin. A static surface through the point can
// not do that: any plane through a point inside the cone of four rays cuts at
// least one of them no farther than the point (up to the range noise, hence
// the margin), so floors and walls seen at grazing angles, the false removals
// of per-voxel ray casting (OctoMap-style counting), are kept by construction.
// A point is dynamic when it was seen through in at least `min_through` scans
// and in at least `through_ratio` times as many scans as it was seen in (a
// return of the quad within `seen_tolerance_m` of it). docs/decisions/029-moving-objects-seen-through-in-the-recording.md.

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <Eigen/Geometry>

namespace adit::products {

struct SeeThroughOptions {
  bool enabled = true;
  double min_range_m = 1.0;        // closer map points are not tested (the payload itself, the crew)
  double max_range_m = 25.0;       // farther ones neither (the rings fan out: 0.9 m apart at 25 m)
  double margin_m = 0.3;           // the four returns must pass the point by this much ...
  double margin_fraction = 0.03;   // ... or by this fraction of its range when larger (range noise, grazing)
  double seen_tolerance_m = 0.1;   // a return of the quad this close to the point's range: seen
  int min_through = 2;             // scans that saw through the point, at least,
  double through_ratio = 1.0;      // and at least this many times the scans that saw it
  int scan_step = 1;               // every n-th scan of the recording is used
  // Two passes (moving_objects.hpp): every coarse_step-th scan over all the
  // candidates finds the suspects (seen through once), then every scan_step-th
  // scan judges only those. 0: one pass over all.
  int coarse_step = 16;
  // In the coarse pass, a point looked at in this many scans (all four returns
  // there, not seen through: seen, or hidden, or grazed), the first of them at
  // least coarse_retire_after_scans coarse scans ago, and never seen through
  // is tested no more (0: every point in every coarse scan). A route that
  // comes back to the same drifts for half an hour would otherwise test each
  // static point again on every lap. The span keeps someone who stood in view
  // for less than a minute (40 coarse scans of a 10 Hz LiDAR) from being
  // retired before they leave. Looks, not sightings, count: a point at a
  // grazing angle is rarely seen and was tested on every lap
  // (docs/decisions/063-products-one-point-per-map-voxel.md).
  int coarse_retire_after_looks = 8;
  int coarse_retire_after_scans = 40;
  // Only the return nearest in direction is compared (a plain per-pixel range
  // image comparison, as Removert's), not the four around: for measuring what
  // the four buy (docs/decisions), not for use.
  bool nearest_return_only = false;
};

// One scan in its sensor's frame: the nearest first return per ring and
// azimuth bin, each bin's firing time, each ring's elevation.
class RangeImage {
 public:
  // `rings` rows, `columns` azimuth bins over 360°.
  RangeImage(int rings, int columns);

  void clear();
  // One return: ring (0 = the lowest elevation), the point in the sensor
  // frame, its firing time after the scan start. Rings outside the image are ignored.
  void add(int ring, const Eigen::Vector3f& point, float time_s);
  // Ends the scan: each ring's elevation (the mean of its returns), rows sorted by it.
  void finish();

  int rings() const { return rings_; }
  int columns() const { return columns_; }
  float column_width_rad() const { return column_width_; }
  // The column of an azimuth (radians, any value).
  int column_of(float azimuth) const;
  // Range of (row in elevation order, column), 0 = no return there.
  float range(int row, int column) const { return range_[static_cast<std::size_t>(row * columns_ + column)]; }
  // Firing time of a column after the scan start (the mean of its returns'); NaN when it has none.
  float column_time(int column) const { return column_time_[static_cast<std::size_t>(column)]; }
  // Elevation of a row (radians, ascending with the row).
  float row_elevation(int row) const { return row_elevation_[static_cast<std::size_t>(row)]; }
  // The row at or below `elevation` whose next row is above it; -1 when outside the rings.
  int row_below(float elevation) const;
  float row_tangent(int row) const { return row_tangent_[static_cast<std::size_t>(row)]; }
  // The same by the elevation's tangent (z / horizontal distance; rings lie within ±80°).
  int row_below_tangent(float tan_elevation) const;

 private:
  int rings_;
  int columns_;
  float column_width_;
  std::vector<float> range_;         // rings × columns: by ring and +inf where none while adding, by row and 0 after finish()
  std::vector<float> scratch_;       // the same for the reordering
  std::vector<float> column_time_;   // sum while adding, mean after finish()
  std::vector<std::uint32_t> column_count_;
  std::vector<double> ring_elevation_sum_;
  std::vector<std::uint32_t> ring_count_;
  std::vector<float> row_elevation_;
  std::vector<float> row_tangent_;
  std::vector<int> ring_of_row_;
  // row_below_tangent's table (finish()): kTangentBins bins from tangent_low_.
  static constexpr std::size_t kTangentBins = 256;
  std::array<std::uint32_t, kTangentBins> row_start_{};
  float tangent_low_ = std::numeric_limits<float>::infinity();
  float inverse_bin_ = 0.0F;
};

// The sensor's pose over one scan: `map_to_sensor[k]` at time k·step_s after
// the scan start (the map frame into the sensor frame).
struct ScanPoses {
  std::vector<Eigen::Isometry3f> map_to_sensor;
  float step_s = 0.0F;
  Eigen::Vector3f sensor_in_map() const { return map_to_sensor.front().inverse().translation(); }
};

// Counts, per map point, the scans that saw through it and the scans that saw it.
class SeeThroughCounter {
 public:
  // `candidate[i]` = 0: point i is never tested (e.g. it is ground). Empty: all are.
  // `retire` true: a point looked at in options.coarse_retire_after_looks
  // scans over options.coarse_retire_after_scans scans of this counter or
  // more, and never seen through, is tested no more (the coarse pass).
  SeeThroughCounter(std::span<const Eigen::Vector3f> map_points, std::span<const std::uint8_t> candidate,
                    const SeeThroughOptions& options, bool retire = false);

  static constexpr float kCell = 2.0F;  // m, the cells the candidates are grouped in

  // One scan (RangeImage::finish() called) with its poses.
  void add_scan(const RangeImage& image, const ScanPoses& poses);

  std::size_t scans() const { return scans_; }
  std::uint16_t through(std::size_t i) const { return through_[i]; }
  std::uint16_t seen(std::size_t i) const { return seen_[i]; }
  // 1 where the point is dynamic (options' rule), 0 elsewhere.
  std::vector<std::uint8_t> dynamic() const;

 private:
  struct Cell {
    Eigen::Vector3f low, high;  // the bounding box of its points
    std::uint32_t begin = 0, end = 0;  // into sorted_ / index_; retired points are swapped past `end`
  };
  std::size_t size_ = 0;
  std::vector<Eigen::Vector3f> sorted_;  // the candidates, cell by cell (scans visit the cells in range)
  std::vector<std::uint32_t> index_;     // each sorted point's index in the map
  std::vector<Cell> cells_;
  std::vector<std::uint64_t> cell_keys_;  // each cell's key, ascending: a scan looks up only the cells in its range
  std::vector<std::uint32_t> in_range_;   // add_scan's: the cells within its range
  SeeThroughOptions options_;
  std::uint16_t retire_after_looks_ = 0;  // 0: never retired
  std::size_t retire_after_scans_ = 0;
  // With retiring: the scans that looked at each point without seeing through
  // it, and the first of them (1, 2, ...; 0: none).
  std::vector<std::uint16_t> looked_;
  std::vector<std::uint32_t> first_looked_;
  std::vector<std::uint16_t> through_;
  std::vector<std::uint16_t> seen_;
  std::size_t scans_ = 0;
};

}  // namespace adit::products
