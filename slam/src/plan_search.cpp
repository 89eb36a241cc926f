#include "adit/slam/plan_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <queue>

namespace adit::slam {
namespace {

double wrap(double a) { return std::remainder(a, 2.0 * std::numbers::pi); }

constexpr int kPerYaw = 3;

// The likelihood quantised to a byte, so that the fields stay in cache; a
// score is the sum over the search points, exact in integers.
using Level = std::uint8_t;
using Sum = std::uint32_t;
constexpr float kLevels = 255.0F;

// One yaw's best kPerYaw cells, best first: a higher score, or the same score
// and an earlier cell in row order (the order the exhaustive search met them).
class YawBest {
 public:
  // `floor`: a score no cell below which can be among the search's peaks.
  explicit YawBest(Sum floor = 0) : floor_(floor) {}
  void insert(Sum score, std::size_t order, int ix, int iy) {
    if (score == 0 || !worse_than(kPerYaw - 1, score, order)) return;
    int j = kPerYaw - 1;
    for (; j > 0 && worse_than(j - 1, score, order); --j) entries_[j] = entries_[j - 1];
    entries_[j] = Entry{score, order, ix, iy};
  }
  // Whether no cell scoring at most `bound` can enter.
  bool closed_to(Sum bound) const {
    const Sum third = entries_[kPerYaw - 1].score;
    return bound == 0 || bound < third || bound < floor_;
  }
  template <typename F>
  void for_each_score(F f) const {
    for (const Entry& e : entries_)
      if (e.score > 0) f(e.score);
  }
  void append_to(std::vector<PlanPeak>& peaks, double yaw, double to_score) const {
    for (const Entry& e : entries_)
      if (e.score > 0) peaks.push_back(PlanPeak{e.score * to_score, e.ix, e.iy, yaw});
  }

 private:
  struct Entry {
    Sum score = 0;  // 0: empty
    std::size_t order = 0;
    int ix = 0;
    int iy = 0;
  };
  bool worse_than(int j, Sum score, std::size_t order) const {
    const Entry& e = entries_[static_cast<std::size_t>(j)];
    return e.score < score || (e.score == score && e.order > order);
  }
  Sum floor_;
  std::array<Entry, kPerYaw> entries_{};
};

// A block of 2^h x 2^h cells from (bx 2^h, by 2^h), and its bound.
struct Block {
  Sum bound = 0;
  int bx = 0;
  int by = 0;
};

bool by_bound(const Block& a, const Block& b) { return a.bound > b.bound; }

// The search's tables: the likelihood padded by the search range (so that no
// lookup needs a bounds check) and its maxima over 2^h x 2^h cells; which
// blocks hold a candidate cell.
class BlockFields {
 public:
  BlockFields(const PlanGrid& plan, int pad, int levels, std::vector<std::uint8_t> candidate)
      : pad_(pad), wp_(plan.width + 2 * pad), hp_(plan.height + 2 * pad), width_(plan.width) {
    fields_.resize(static_cast<std::size_t>(levels) + 1);
    std::vector<Level>& field = fields_[0];
    field.assign(static_cast<std::size_t>(wp_) * static_cast<std::size_t>(hp_), 0);
    for (int iy = 0; iy < plan.height; ++iy)
      for (int ix = 0; ix < plan.width; ++ix)
        field[index(ix + pad, iy + pad)] =
            static_cast<Level>(std::lround(std::clamp(plan.likelihood[plan.index(ix, iy)], 0.0F, 1.0F) * kLevels));
    // Hess et al.'s precomputation grids, each from the one below: the
    // maximum over 2^h cells is that of four 2^(h-1) windows.
    for (int h = 1; h <= levels; ++h) {
      const std::vector<Level>& below = fields_[static_cast<std::size_t>(h - 1)];
      std::vector<Level>& f = fields_[static_cast<std::size_t>(h)];
      f.assign(below.size(), 0);
      const int s = 1 << (h - 1);
      for (int y = 0; y < hp_; ++y)
        for (int x = 0; x < wp_; ++x) {
          Level m = below[index(x, y)];
          if (x + s < wp_) m = std::max(m, below[index(x + s, y)]);
          if (y + s < hp_) m = std::max(m, below[index(x, y + s)]);
          if (x + s < wp_ && y + s < hp_) m = std::max(m, below[index(x + s, y + s)]);
          f[index(x, y)] = m;
        }
    }
    has_.resize(fields_.size());
    dims_.resize(fields_.size());
    has_[0] = std::move(candidate);
    dims_[0] = {plan.width, plan.height};
    for (std::size_t h = 1; h < has_.size(); ++h) {
      const auto [wb, hb] = dims_[h - 1];
      const int w = (wb + 1) / 2;
      const int ht = (hb + 1) / 2;
      dims_[h] = {w, ht};
      has_[h].assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(ht), 0);
      for (int y = 0; y < hb; ++y)
        for (int x = 0; x < wb; ++x)
          if (has_[h - 1][static_cast<std::size_t>(y) * static_cast<std::size_t>(wb) + static_cast<std::size_t>(x)] != 0)
            has_[h][static_cast<std::size_t>(y / 2) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x / 2)] = 1;
    }
  }

  int levels() const { return static_cast<int>(fields_.size()) - 1; }
  int row_stride() const { return wp_; }
  std::pair<int, int> blocks(int h) const { return dims_[static_cast<std::size_t>(h)]; }
  bool has(int h, int bx, int by) const {
    const auto [w, ht] = dims_[static_cast<std::size_t>(h)];
    return bx < w && by < ht &&
           has_[static_cast<std::size_t>(h)][static_cast<std::size_t>(by) * static_cast<std::size_t>(w) + static_cast<std::size_t>(bx)] != 0;
  }
  // The sum over the search points (their cell offsets) of the level-h field
  // at the block's first cell: the score of the cell at h = 0, otherwise at
  // least that of every cell of the block (each term is at least as large;
  // integer sums are exact). Four partial sums, so that the loads need not
  // wait on one running sum.
  Sum bound(int h, int bx, int by, std::span<const std::int64_t> offsets) const {
    const Level* base = fields_[static_cast<std::size_t>(h)].data() + index((bx << h) + pad_, (by << h) + pad_);
    std::array<Sum, 4> lane{};
    std::size_t i = 0;
    for (; i + 4 <= offsets.size(); i += 4)
      for (std::size_t l = 0; l < 4; ++l) lane[l] += base[offsets[i + l]];
    for (; i < offsets.size(); ++i) lane[0] += base[offsets[i]];
    return (lane[0] + lane[1]) + (lane[2] + lane[3]);
  }
  std::size_t order(int ix, int iy) const {
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(ix);
  }

 private:
  std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(wp_) + static_cast<std::size_t>(x);
  }
  int pad_;
  int wp_;
  int hp_;
  int width_;
  std::vector<std::vector<Level>> fields_;
  std::vector<std::vector<std::uint8_t>> has_;
  std::vector<std::pair<int, int>> dims_;
};

// Depth first, the most promising block first (Hess et al., algorithm 3).
void descend(const BlockFields& fields, int h, const Block& block, std::span<const std::int64_t> offsets,
             YawBest& best, std::uint64_t& sums) {
  std::array<Block, 4> children{};
  std::size_t n = 0;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int bx = 2 * block.bx + i;
      const int by = 2 * block.by + j;
      if (!fields.has(h - 1, bx, by)) continue;
      const Block c{fields.bound(h - 1, bx, by, offsets), bx, by};
      ++sums;
      std::size_t at = n++;  // kept in order of bound, highest first
      for (; at > 0 && by_bound(c, children[at - 1]); --at) children[at] = children[at - 1];
      children[at] = c;
    }
  for (std::size_t k = 0; k < n; ++k) {
    const Block& c = children[k];
    if (best.closed_to(c.bound)) break;
    if (h - 1 == 0)
      best.insert(c.bound, fields.order(c.bx, c.by), c.bx, c.by);
    else
      descend(fields, h - 1, c, offsets, best, sums);
  }
}

}  // namespace

PlanSearch search_plan(std::span<const Eigen::Vector3f> walls, const PlanGrid& plan,
                       const std::optional<LocalisationHint>& hint, const LocalisationConfig& config) {
  PlanSearch out;
  // Search points: the walls' horizontal positions within range, spread evenly.
  std::vector<Eigen::Vector2f> flat;
  for (const auto& p : walls)
    if (p.head<2>().norm() <= config.search_range_m) flat.push_back(p.head<2>());
  if (flat.size() > config.max_search_points) {
    std::vector<Eigen::Vector2f> kept;
    const double step = static_cast<double>(flat.size()) / static_cast<double>(config.max_search_points);
    for (std::size_t k = 0; k < config.max_search_points; ++k) kept.push_back(flat[static_cast<std::size_t>(static_cast<double>(k) * step)]);
    flat.swap(kept);
  }
  // Candidate cells: a floor, clear of walls, in the hint's disc.
  std::vector<std::uint8_t> candidate(static_cast<std::size_t>(plan.width) * static_cast<std::size_t>(plan.height), 0);
  std::vector<std::pair<int, int>> cells;  // row order
  for (int iy = 0; iy < plan.height; ++iy) {
    for (int ix = 0; ix < plan.width; ++ix) {
      const std::size_t c = plan.index(ix, iy);
      if (std::isnan(plan.floor_z[c]) || plan.wall_distance[c] < config.min_wall_clearance_m) continue;
      if (hint) {
        const Eigen::Vector2d centre(plan.origin.x() + (ix + 0.5) * plan.cell_m, plan.origin.y() + (iy + 0.5) * plan.cell_m);
        if ((centre - hint->position).norm() > hint->radius_m) continue;
      }
      candidate[c] = 1;
      cells.emplace_back(ix, iy);
    }
  }
  if (cells.empty() || flat.empty()) return out;
  const int pad = static_cast<int>(std::ceil(config.search_range_m / plan.cell_m)) + 2;
  const BlockFields fields(plan, pad, std::max(0, config.search_levels), std::move(candidate));
  double yaw_lo = 0.0, yaw_span = 2.0 * std::numbers::pi;
  if (hint && hint->yaw_tolerance_rad < std::numbers::pi) {
    yaw_lo = hint->yaw_rad - hint->yaw_tolerance_rad;
    yaw_span = 2.0 * hint->yaw_tolerance_rad;
  }
  const int yaws = std::max(1, static_cast<int>(std::ceil(yaw_span / config.yaw_step_rad)));
  out.cells = static_cast<std::uint64_t>(cells.size()) * static_cast<std::uint64_t>(yaws);
  std::vector<std::int64_t> offsets(flat.size());
  const float inv_cell = 1.0F / plan.cell_m;
  const double to_score = 1.0 / (static_cast<double>(kLevels) * static_cast<double>(flat.size()));
  const int top = fields.levels();
  const auto [top_w, top_h] = fields.blocks(top);
  std::vector<Block> blocks;
  blocks.reserve(static_cast<std::size_t>(top_w) * static_cast<std::size_t>(top_h));
  const std::int64_t wp = fields.row_stride();
  const auto yaw_at = [&](int k) { return yaw_lo + (k + 0.5) * yaw_span / yaws; };
  const auto offsets_at = [&](int k) {
    const Eigen::Matrix2f m = Eigen::Rotation2Df(static_cast<float>(yaw_at(k))).toRotationMatrix();
    for (std::size_t i = 0; i < flat.size(); ++i) {
      // The cell centre is the origin: a point's cell is its offset rounded.
      const Eigen::Vector2f q = m * flat[i] * inv_cell;
      offsets[i] = static_cast<std::int64_t>(std::lround(q.y())) * wp + std::lround(q.x());
    }
  };
  const auto top_blocks = [&] {
    blocks.clear();
    for (int by = 0; by < top_h; ++by)
      for (int bx = 0; bx < top_w; ++bx)
        if (fields.has(top, bx, by)) blocks.push_back(Block{fields.bound(top, bx, by, offsets), bx, by});
    out.sums += blocks.size();
  };
  std::vector<PlanPeak> peaks;
  if (top == 0) {  // every cell of every yaw, in row order
    for (int k = 0; k < yaws; ++k) {
      offsets_at(k);
      YawBest best;
      for (const auto& [ix, iy] : cells) best.insert(fields.bound(0, ix, iy, offsets), fields.order(ix, iy), ix, iy);
      out.sums += cells.size();
      best.append_to(peaks, yaw_at(k), to_score);
    }
  } else {
    // Across yaws, a floor: the suppression below keeps its peaks among the
    // best `window` entries of all yaws (each peak kept passes over at most
    // kPerYaw entries in each yaw step within distinct_rad of it), so no cell
    // scoring below the window-th best entry found so far can be a peak. The
    // yaws go in the order of their best block's bound, so it rises early.
    const double step = yaw_span / yaws;
    const int yaws_near = std::min(yaws, 2 * static_cast<int>(std::ceil(config.distinct_rad / step)) + 1);
    const std::size_t window = static_cast<std::size_t>(std::max(1, config.hypotheses)) * kPerYaw *
                               static_cast<std::size_t>(yaws_near);
    std::vector<std::pair<Sum, int>> yaw_order;
    yaw_order.reserve(static_cast<std::size_t>(yaws));
    for (int k = 0; k < yaws; ++k) {
      offsets_at(k);
      top_blocks();
      Sum most = 0;
      for (const Block& b : blocks) most = std::max(most, b.bound);
      yaw_order.emplace_back(most, k);
    }
    std::sort(yaw_order.begin(), yaw_order.end(), [](const auto& a, const auto& b) {
      return a.first > b.first || (a.first == b.first && a.second < b.second);
    });
    std::priority_queue<Sum, std::vector<Sum>, std::greater<>> kept_scores;  // the best `window`, lowest on top
    for (const auto& [most, k] : yaw_order) {
      const Sum floor = kept_scores.size() == window ? kept_scores.top() : 0;
      if (most == 0 || most < floor) break;
      offsets_at(k);
      top_blocks();
      std::sort(blocks.begin(), blocks.end(), by_bound);
      YawBest best(floor);
      for (const Block& b : blocks) {
        if (best.closed_to(b.bound)) break;
        descend(fields, top, b, offsets, best, out.sums);
      }
      best.append_to(peaks, yaw_at(k), to_score);
      // Each entry at most the yaw's true one of its rank: the floor stays a lower bound.
      best.for_each_score([&](Sum score) {
        if (kept_scores.size() < window) {
          kept_scores.push(score);
        } else if (score > kept_scores.top()) {
          kept_scores.pop();
          kept_scores.push(score);
        }
      });
    }
  }
  // Best first; equal scores in yaw, then row order, whatever order the yaws were searched in.
  std::sort(peaks.begin(), peaks.end(), [](const PlanPeak& a, const PlanPeak& b) {
    if (a.score != b.score) return a.score > b.score;
    if (a.yaw != b.yaw) return a.yaw < b.yaw;
    return a.iy != b.iy ? a.iy < b.iy : a.ix < b.ix;
  });
  // Non-maximum suppression: a peak near a better one is the same place.
  for (const PlanPeak& p : peaks) {
    const bool near = std::any_of(out.peaks.begin(), out.peaks.end(), [&](const PlanPeak& q) {
      const double d = plan.cell_m * std::hypot(p.ix - q.ix, p.iy - q.iy);
      return d < config.distinct_m && std::abs(wrap(p.yaw - q.yaw)) < config.distinct_rad;
    });
    if (!near) out.peaks.push_back(p);
    if (static_cast<int>(out.peaks.size()) == config.hypotheses) break;
  }
  return out;
}

}  // namespace adit::slam
