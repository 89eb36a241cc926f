#pragma once
// Counter-based random numbers: every draw is a pure function of (seed,
// stream, index), so results do not depend on evaluation order or threads.
// SplitMix64's finaliser (Steele, Lea, Flood, "Fast splittable pseudorandom
// number generators", OOPSLA 2014) mixes the counter; Box–Muller turns two
// uniforms into a normal deviate; value noise (Perlin 1985 style lattice,
// smoothstep-interpolated) gives the rough rock.

#include <cmath>
#include <cstdint>
#include <numbers>

namespace adit::sim {

constexpr std::uint64_t mix64(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

constexpr std::uint64_t hash3(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  return mix64(mix64(mix64(seed) ^ stream) ^ index);
}

// The draws of one (seed, stream) with its key mixed once: for hot loops, one
// mix64 per draw instead of three, the same numbers as the free functions.
class NoiseStream {
 public:
  constexpr NoiseStream(std::uint64_t seed, std::uint64_t stream) : key_(mix64(mix64(seed) ^ stream)) {}

  // Uniform in [0, 1) with 53 random bits.
  constexpr double uniform(std::uint64_t index) const {
    return static_cast<double>(mix64(key_ ^ index) >> 11) * 0x1.0p-53;
  }
  double gaussian(std::uint64_t index) const {
    const double u1 = 1.0 - uniform(2 * index);  // (0, 1]
    const double u2 = uniform(2 * index + 1);
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  std::uint64_t key_;
};

constexpr double uniform(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  return NoiseStream(seed, stream).uniform(index);
}

inline double gaussian(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  return NoiseStream(seed, stream).gaussian(index);
}

// Smooth value noise in [-1, 1] on a unit lattice.
inline double value_noise3(std::uint64_t seed, double x, double y, double z) {
  const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
  const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy), iz = static_cast<std::int64_t>(fz);
  const auto s = [](double t) { return t * t * (3.0 - 2.0 * t); };
  const double tx = s(x - fx), ty = s(y - fy), tz = s(z - fz);
  const auto lattice = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
    const auto key = static_cast<std::uint64_t>(i) * 0x8DA6B343ULL ^ static_cast<std::uint64_t>(j) * 0xD8163841ULL ^
                     static_cast<std::uint64_t>(k) * 0xCB1AB31FULL;
    return 2.0 * uniform(seed, 0x6E6F697365ULL, key) - 1.0;
  };
  double v[2][2][2];
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) v[i][j][k] = lattice(ix + i, iy + j, iz + k);
  const auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
  const double x00 = lerp(v[0][0][0], v[1][0][0], tx), x10 = lerp(v[0][1][0], v[1][1][0], tx);
  const double x01 = lerp(v[0][0][1], v[1][0][1], tx), x11 = lerp(v[0][1][1], v[1][1][1], tx);
  return lerp(lerp(x00, x10, ty), lerp(x01, x11, ty), tz);
}

}  // namespace adit::sim
