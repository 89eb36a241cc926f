#pragma once
// A set of voxels (integer indices) for fast membership tests along rays.
// Voxels are kept in bricks of 4 x 4 x 4, one 64-bit mask a brick (as
// OpenVDB's leaf masks, Museth 2013, or a bitmask per block in Voxblox), in
// one flat open-addressing table (linear probing, Knuth TAOCP vol. 3 §6.4,
// Fibonacci hashing). A walk along a ray stays in one brick for several
// steps: `BrickReader` keeps the brick last looked up, so most tests are a
// bit test with no memory access. Built once, then only read. With
// std::unordered_set of voxel keys, the products' line-of-sight test spent
// most of its time waiting for the table's cache lines.

#include <algorithm>
#include <bit>
#include <cstdint>
#include <utility>
#include <vector>

namespace adit::products {

struct VoxelIndex {
  std::int64_t x = 0, y = 0, z = 0;
};

class VoxelBrickSet {
 public:
  // Room for about `voxels` voxels before the table doubles.
  explicit VoxelBrickSet(std::size_t voxels)
      : slots_(std::bit_ceil(std::max<std::size_t>(voxels / 2, 16))), shift_(64 - std::countr_zero(slots_.size())) {}

  // Adds a voxel; true when it was not in the set before.
  bool insert(const VoxelIndex& v) {
    if (2 * (bricks_ + 1) > slots_.size()) grow();
    Slot& s = find_or_add(brick_key(v));
    const std::uint64_t bit = bit_of(v);
    const bool added = (s.mask & bit) == 0;
    s.mask |= bit;
    return added;
  }

  bool contains(const VoxelIndex& v) const { return (mask_of(brick_key(v)) & bit_of(v)) != 0; }

  std::size_t bricks() const { return bricks_; }

  // Membership tests that remember the last brick: for a walk along a line.
  class BrickReader {
   public:
    explicit BrickReader(const VoxelBrickSet& set) : set_(set) {}
    bool contains(const VoxelIndex& v) {
      const std::uint64_t key = brick_key(v);
      if (key != key_) {
        key_ = key;
        mask_ = set_.mask_of(key);
      }
      return (mask_ & bit_of(v)) != 0;
    }

   private:
    const VoxelBrickSet& set_;
    std::uint64_t key_ = kEmpty;
    std::uint64_t mask_ = 0;
  };

 private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // no brick key has all bits set (bit 63 is 0)
  struct Slot {
    std::uint64_t key = kEmpty;
    std::uint64_t mask = 0;
  };

  // 21 bits a brick coordinate (±4.2 M bricks), x most significant.
  static std::uint64_t brick_key(const VoxelIndex& v) {
    const auto c = [](std::int64_t i) { return static_cast<std::uint64_t>((i >> 2) + (1 << 20)) & 0x1FFFFF; };
    return (c(v.x) << 42) | (c(v.y) << 21) | c(v.z);
  }
  static std::uint64_t bit_of(const VoxelIndex& v) {
    return std::uint64_t{1} << ((v.x & 3) | ((v.y & 3) << 2) | ((v.z & 3) << 4));
  }
  std::size_t slot_of(std::uint64_t key) const { return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ULL) >> shift_); }

  std::uint64_t mask_of(std::uint64_t key) const {
    for (std::size_t i = slot_of(key);; i = (i + 1) & (slots_.size() - 1)) {
      if (slots_[i].key == key) return slots_[i].mask;
      if (slots_[i].key == kEmpty) return 0;
    }
  }
  Slot& find_or_add(std::uint64_t key) {
    for (std::size_t i = slot_of(key);; i = (i + 1) & (slots_.size() - 1)) {
      if (slots_[i].key == key) return slots_[i];
      if (slots_[i].key == kEmpty) {
        slots_[i].key = key;
        ++bricks_;
        return slots_[i];
      }
    }
  }
  void grow() {
    std::vector<Slot> old(2 * slots_.size());
    old.swap(slots_);
    shift_ = 64 - std::countr_zero(slots_.size());
    bricks_ = 0;
    for (const Slot& s : old)
      if (s.key != kEmpty) find_or_add(s.key).mask = s.mask;
  }

  std::vector<Slot> slots_;
  int shift_;
  std::size_t bricks_ = 0;
};

}  // namespace adit::products
