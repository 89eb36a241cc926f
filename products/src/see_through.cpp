#include "adit/products/see_through.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "adit/common/error.hpp"
#include "adit/slam/voxel_key.hpp"

namespace adit::products {
namespace {

constexpr float kTwoPi = 6.283185307179586F;

// A cell's index along one axis, and its key: 21 bits an axis (±2,097 km at
// 2 m), x most significant, so the cells of one (x, y) column are contiguous
// in key order, lowest z first.
std::int64_t cell_index(float v) { return static_cast<std::int64_t>(std::floor(v / SeeThroughCounter::kCell)); }
std::uint64_t cell_key(std::int64_t x, std::int64_t y, std::int64_t z) {
  const auto c = [](std::int64_t i) { return static_cast<std::uint64_t>(i + (1 << 20)) & 0x1FFFFF; };
  return (c(x) << 42) | (c(y) << 21) | c(z);
}

// atan2 within 1e-5 rad (a minimax polynomial for atan on [-1, 1], octants
// by symmetry): the columns are 3e-3 rad wide, and libm's atan2 would be most
// of the time of a pass that projects every map point into every scan.
inline __attribute__((always_inline)) float fast_atan2(float y, float x) {
  const float ax = std::abs(x), ay = std::abs(y);
  const float big = std::max(ax, ay);
  if (big == 0.0F) return 0.0F;
  const float a = std::min(ax, ay) / big;
  const float s = a * a;
  float r = a * (0.99997726F + s * (-0.33262347F + s * (0.19354346F + s * (-0.11643287F + s * (0.05265332F + s * -0.01172120F)))));
  if (ay > ax) r = 1.57079637F - r;
  if (x < 0.0F) r = 3.14159274F - r;
  return y < 0.0F ? -r : r;
}

}  // namespace

RangeImage::RangeImage(int rings, int columns)
    : rings_(rings), columns_(columns), column_width_(kTwoPi / static_cast<float>(std::max(columns, 1))) {
  if (rings < 2 || columns < 4) throw InputError("range image", "", "needs at least 2 rings and 4 azimuth bins");
  const auto n = static_cast<std::size_t>(rings) * static_cast<std::size_t>(columns);
  range_.resize(n);
  scratch_.resize(n);
  column_time_.resize(static_cast<std::size_t>(columns));
  column_count_.resize(static_cast<std::size_t>(columns));
  ring_elevation_sum_.resize(static_cast<std::size_t>(rings));
  ring_count_.resize(static_cast<std::size_t>(rings));
  row_elevation_.resize(static_cast<std::size_t>(rings));
  row_tangent_.resize(static_cast<std::size_t>(rings));
  ring_of_row_.resize(static_cast<std::size_t>(rings));
  clear();
}

void RangeImage::clear() {
  // +inf while adding (the nearest return is then one min), 0 again in finish().
  std::fill(range_.begin(), range_.end(), std::numeric_limits<float>::infinity());
  std::fill(column_time_.begin(), column_time_.end(), 0.0F);
  std::fill(column_count_.begin(), column_count_.end(), 0U);
  std::fill(ring_elevation_sum_.begin(), ring_elevation_sum_.end(), 0.0);
  std::fill(ring_count_.begin(), ring_count_.end(), 0U);
  std::fill(row_elevation_.begin(), row_elevation_.end(), std::numeric_limits<float>::infinity());
}

int RangeImage::column_of(float azimuth) const {
  float a = azimuth;  // from atan2: within one turn of [0, 2π)
  if (a < 0.0F) a += kTwoPi;
  if (a >= kTwoPi) a -= kTwoPi;
  const int c = static_cast<int>(a / column_width_);
  return c >= columns_ ? columns_ - 1 : c;
}

void RangeImage::add(int ring, const Eigen::Vector3f& p, float time_s) {
  if (ring < 0 || ring >= rings_) return;
  const float range = p.norm();
  if (!(range > 0.0F) || !std::isfinite(range)) return;
  const int c = column_of(fast_atan2(p.y(), p.x()));
  float& cell = range_[static_cast<std::size_t>(ring * columns_ + c)];
  cell = std::min(cell, range);
  column_time_[static_cast<std::size_t>(c)] += time_s;
  ++column_count_[static_cast<std::size_t>(c)];
  ring_elevation_sum_[static_cast<std::size_t>(ring)] += std::asin(std::clamp(p.z() / range, -1.0F, 1.0F));
  ++ring_count_[static_cast<std::size_t>(ring)];
}

void RangeImage::finish() {
  for (std::size_t c = 0; c < column_time_.size(); ++c)
    column_time_[c] = column_count_[c] > 0 ? column_time_[c] / static_cast<float>(column_count_[c])
                                           : std::numeric_limits<float>::quiet_NaN();
  // Rows in order of elevation (rings without returns last, at +inf: never bracketing).
  std::vector<float>& elevation = row_elevation_;  // by ring first, then by row
  for (std::size_t r = 0; r < ring_count_.size(); ++r)
    elevation[r] = ring_count_[r] > 0 ? static_cast<float>(ring_elevation_sum_[r] / ring_count_[r])
                                      : std::numeric_limits<float>::infinity();
  std::iota(ring_of_row_.begin(), ring_of_row_.end(), 0);
  std::sort(ring_of_row_.begin(), ring_of_row_.end(), [&](int a, int b) {
    return elevation[static_cast<std::size_t>(a)] < elevation[static_cast<std::size_t>(b)];
  });
  const auto cols = static_cast<std::size_t>(columns_);
  for (std::size_t row = 0; row < ring_of_row_.size(); ++row) {
    const auto ring = static_cast<std::size_t>(ring_of_row_[row]);
    std::transform(range_.begin() + static_cast<std::ptrdiff_t>(ring * cols),
                   range_.begin() + static_cast<std::ptrdiff_t>((ring + 1) * cols),
                   scratch_.begin() + static_cast<std::ptrdiff_t>(row * cols),
                   [](float r) { return std::isinf(r) ? 0.0F : r; });  // a bin without a return: 0
  }
  range_.swap(scratch_);
  // Elevations by row: rebuilt into scratch order through the ring indices.
  for (std::size_t row = 0; row < ring_of_row_.size(); ++row)
    scratch_[row] = elevation[static_cast<std::size_t>(ring_of_row_[row])];
  std::copy_n(scratch_.begin(), ring_of_row_.size(), elevation.begin());
  for (std::size_t row = 0; row < ring_of_row_.size(); ++row)
    row_tangent_[row] = std::isfinite(elevation[row]) ? std::tan(elevation[row]) : std::numeric_limits<float>::infinity();
  // The rows' tangents in kTangentBins equal bins from the lowest to the
  // highest finite one, each with the first row above its start: the
  // projection of every map point into every scan looks its row up there,
  // not by a binary search with its mispredicted branches.
  const auto end = row_tangent_.begin() + rings_;
  tangent_low_ = row_tangent_.front();
  float high = tangent_low_;  // the highest finite tangent (rows without returns sort last, at +inf)
  for (const float t : row_tangent_)
    if (std::isfinite(t)) high = t;
  inverse_bin_ = std::isfinite(tangent_low_) && high > tangent_low_
                     ? static_cast<float>(kTangentBins) / (high - tangent_low_)
                     : 0.0F;
  for (std::size_t b = 0; b < kTangentBins; ++b) {
    const float start = tangent_low_ + (inverse_bin_ > 0.0F ? static_cast<float>(b) / inverse_bin_ : 0.0F);
    row_start_[b] = static_cast<std::uint32_t>(std::upper_bound(row_tangent_.begin(), end, start) - row_tangent_.begin());
  }
}

int RangeImage::row_below_tangent(float tan_e) const {
  // std::upper_bound over the rows' tangents, started from the table's guess
  // for this tangent's bin and walked the row or two to the exact answer.
  if (!(tan_e >= tangent_low_)) return -1;  // below the lowest row (or no rows, or NaN)
  const float bin = (tan_e - tangent_low_) * inverse_bin_;
  auto above = static_cast<std::size_t>(
      row_start_[bin < static_cast<float>(kTangentBins - 1) ? static_cast<std::size_t>(bin) : kTangentBins - 1]);
  const auto rings = static_cast<std::size_t>(rings_);
  while (above > 0 && row_tangent_[above - 1] > tan_e) --above;
  while (above < rings && !(row_tangent_[above] > tan_e)) ++above;
  if (above == 0 || above == rings || !std::isfinite(row_tangent_[above])) return -1;
  return static_cast<int>(above) - 1;
}

int RangeImage::row_below(float e) const {
  const auto end = row_elevation_.begin() + rings_;
  const auto above = std::upper_bound(row_elevation_.begin(), end, e);
  if (above == row_elevation_.begin() || above == end || !std::isfinite(*above)) return -1;
  return static_cast<int>(above - row_elevation_.begin()) - 1;
}

SeeThroughCounter::SeeThroughCounter(std::span<const Eigen::Vector3f> map_points, std::span<const std::uint8_t> candidate,
                                     const SeeThroughOptions& options, bool retire)
    : size_(map_points.size()),
      options_(options),
      retire_after_looks_(retire ? static_cast<std::uint16_t>(std::clamp(options.coarse_retire_after_looks, 0, 65535)) : 0),
      retire_after_scans_(static_cast<std::size_t>(std::max(options.coarse_retire_after_scans, 0))),
      through_(map_points.size(), 0),
      seen_(map_points.size(), 0) {
  if (retire_after_looks_ > 0) {
    looked_.assign(map_points.size(), 0);
    first_looked_.assign(map_points.size(), 0);
  }
  if (!candidate.empty() && candidate.size() != map_points.size())
    throw InputError("see-through", "", "the candidate flags do not match the map points");
  // The candidates grouped by cell (sorted by the cell's key), so that a scan
  // visits only the cells within its range and walks memory in order.
  const auto key = [](const Eigen::Vector3f& p) { return cell_key(cell_index(p.x()), cell_index(p.y()), cell_index(p.z())); };
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
  keyed.reserve(map_points.size());
  for (std::size_t i = 0; i < map_points.size(); ++i)
    if (candidate.empty() || candidate[i]) keyed.emplace_back(key(map_points[i]), static_cast<std::uint32_t>(i));
  std::sort(keyed.begin(), keyed.end());
  sorted_.reserve(keyed.size());
  index_.reserve(keyed.size());
  for (std::size_t k = 0; k < keyed.size(); ++k) {
    const Eigen::Vector3f& p = map_points[keyed[k].second];
    if (k == 0 || keyed[k].first != keyed[k - 1].first) {
      cells_.push_back({p, p, static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(k)});
      cell_keys_.push_back(keyed[k].first);
    }
    Cell& c = cells_.back();
    c.low = c.low.cwiseMin(p);
    c.high = c.high.cwiseMax(p);
    c.end = static_cast<std::uint32_t>(k + 1);
    sorted_.push_back(p);
    index_.push_back(keyed[k].second);
  }
}

void SeeThroughCounter::add_scan(const RangeImage& image, const ScanPoses& poses) {
  if (poses.map_to_sensor.empty()) return;
  ++scans_;
  const std::size_t mid = poses.map_to_sensor.size() / 2;
  const Eigen::Isometry3f& middle = poses.map_to_sensor[mid];
  const Eigen::Vector3f centre = middle.inverse().translation();
  const float min2 = static_cast<float>(options_.min_range_m * options_.min_range_m);
  const float max2 = static_cast<float>(options_.max_range_m * options_.max_range_m);
  const float w = image.column_width_rad();
  const int cols = image.columns();
  const auto margin = static_cast<float>(options_.margin_m);
  const auto fraction = static_cast<float>(options_.margin_fraction);
  const auto tolerance = static_cast<float>(options_.seen_tolerance_m);
  const int last_pose = static_cast<int>(poses.map_to_sensor.size()) - 1;
  const float inverse_step = poses.step_s > 0.0F ? 1.0F / poses.step_s : 0.0F;
  // The cells within the range's box: per (x, y) column, the span of keys
  // from its lowest z to its highest (a cell outside the box is out of range).
  const float reach = static_cast<float>(options_.max_range_m);
  const std::int64_t z_low = cell_index(centre.z() - reach), z_high = cell_index(centre.z() + reach);
  in_range_.clear();
  for (std::int64_t x = cell_index(centre.x() - reach); x <= cell_index(centre.x() + reach); ++x)
    for (std::int64_t y = cell_index(centre.y() - reach); y <= cell_index(centre.y() + reach); ++y) {
      const std::uint64_t last = cell_key(x, y, z_high);
      for (auto it = std::lower_bound(cell_keys_.begin(), cell_keys_.end(), cell_key(x, y, z_low));
           it != cell_keys_.end() && *it <= last; ++it)
        in_range_.push_back(static_cast<std::uint32_t>(it - cell_keys_.begin()));
    }
  // One candidate (at s in sorted_) against this scan.
  const auto test = [&](std::uint32_t s) {
    const Eigen::Vector3f& p = sorted_[s];
    const std::size_t i = index_[s];
    const float d2 = (p - centre).squaredNorm();
    if (d2 < min2 || d2 > max2) return;
    // The sensor's pose when this azimuth was fired.
    Eigen::Vector3f q = middle * p;
    float azimuth = fast_atan2(q.y(), q.x());
    if (inverse_step > 0.0F) {
      const float t = image.column_time(image.column_of(azimuth));
      if (std::isfinite(t)) {
        const int k = std::clamp(static_cast<int>(t * inverse_step + 0.5F), 0, last_pose);
        if (k != static_cast<int>(mid)) {
          q = poses.map_to_sensor[static_cast<std::size_t>(k)] * p;
          azimuth = fast_atan2(q.y(), q.x());
        }
      }
    }
    const float rho2 = q.x() * q.x() + q.y() * q.y();
    const float rho = std::sqrt(rho2);
    const float range = std::sqrt(rho2 + q.z() * q.z());
    if (!(rho > 0.0F)) return;
    const int row = image.row_below_tangent(q.z() / rho);
    if (row < 0) return;
    // The columns whose centres bracket the azimuth.
    float a = azimuth;
    if (a < 0.0F) a += kTwoPi;
    const int c0 = slam::floor_to_int(a / w - 0.5F);  // ≥ -0.5: in int range
    const int left = c0 < 0 ? c0 + cols : c0 >= cols ? c0 - cols : c0;
    const int right = left + 1 == cols ? 0 : left + 1;
    float r[4] = {image.range(row, left), image.range(row, right), image.range(row + 1, left),
                  image.range(row + 1, right)};
    if (options_.nearest_return_only) {
      const int col = a / w - static_cast<float>(c0) - 0.5F < 0.5F ? left : right;
      const int nearest_row = q.z() / rho - image.row_tangent(row) < image.row_tangent(row + 1) - q.z() / rho ? row : row + 1;
      r[0] = r[1] = r[2] = r[3] = image.range(nearest_row, col);
    }
    float nearest = r[0];
    bool seen = false;
    bool known = true;
    for (const float x : r) {
      known = known && x > 0.0F;
      nearest = std::min(nearest, x);
      seen = seen || std::abs(x - range) <= tolerance;
    }
    if (!known) return;  // a bin without a return says nothing
    constexpr std::uint16_t kMost = std::numeric_limits<std::uint16_t>::max();
    const bool through = !seen && nearest > range + std::max(margin, fraction * range);
    if (seen && seen_[i] < kMost) ++seen_[i];
    if (through && through_[i] < kMost) ++through_[i];
    if (!through && !looked_.empty()) {
      if (looked_[i] < kMost) ++looked_[i];
      if (first_looked_[i] == 0) first_looked_[i] = static_cast<std::uint32_t>(scans_);
    }
  };
  const auto retired = [&](std::size_t i) {
    return retire_after_looks_ > 0 && through_[i] == 0 && looked_[i] >= retire_after_looks_ &&
           scans_ - first_looked_[i] >= retire_after_scans_;
  };
  for (const std::uint32_t c : in_range_) {
    Cell& cell = cells_[c];
    // The nearest and farthest distances of the cell's box from the sensor.
    const Eigen::Vector3f near = centre.cwiseMax(cell.low).cwiseMin(cell.high) - centre;
    const Eigen::Vector3f far = (centre - cell.low).cwiseAbs().cwiseMax((cell.high - centre).cwiseAbs());
    if (near.squaredNorm() > max2 || far.squaredNorm() < min2) continue;
    for (std::uint32_t s = cell.begin; s < cell.end;) {
      if (retired(index_[s])) {
        // Retired for good (nothing tests it again, so its counts stay): it
        // leaves the cell's tested span, swapped past its end; the point
        // swapped in is looked at next.
        --cell.end;
        std::swap(sorted_[s], sorted_[cell.end]);
        std::swap(index_[s], index_[cell.end]);
        continue;
      }
      test(s);
      ++s;
    }
  }
}

std::vector<std::uint8_t> SeeThroughCounter::dynamic() const {
  std::vector<std::uint8_t> out(size_, 0);
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = through_[i] >= options_.min_through &&
                     static_cast<double>(through_[i]) >= options_.through_ratio * static_cast<double>(seen_[i])
                 ? 1
                 : 0;
  return out;
}

}  // namespace adit::products
