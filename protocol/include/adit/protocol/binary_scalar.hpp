#pragma once
// A little-endian binary number in a file's record (PLY, PCD, LAS): its type,
// its size, and its value as a double. The host is little-endian, as the files.

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace adit::protocol {

enum class Scalar : std::uint8_t { i8, u8, i16, u16, i32, u32, i64, u64, f32, f64 };

namespace detail {
template <typename T>
double load_as_double(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return static_cast<double>(v);
}
}  // namespace detail

inline std::size_t scalar_size(Scalar t) {
  switch (t) {
    case Scalar::i8: case Scalar::u8: return 1;
    case Scalar::i16: case Scalar::u16: return 2;
    case Scalar::i32: case Scalar::u32: case Scalar::f32: return 4;
    case Scalar::i64: case Scalar::u64: case Scalar::f64: return 8;
  }
  return 0;
}

inline double read_scalar(Scalar t, const char* p) {
  switch (t) {
    case Scalar::i8: return detail::load_as_double<std::int8_t>(p);
    case Scalar::u8: return detail::load_as_double<std::uint8_t>(p);
    case Scalar::i16: return detail::load_as_double<std::int16_t>(p);
    case Scalar::u16: return detail::load_as_double<std::uint16_t>(p);
    case Scalar::i32: return detail::load_as_double<std::int32_t>(p);
    case Scalar::u32: return detail::load_as_double<std::uint32_t>(p);
    case Scalar::i64: return detail::load_as_double<std::int64_t>(p);
    case Scalar::u64: return detail::load_as_double<std::uint64_t>(p);
    case Scalar::f32: return detail::load_as_double<float>(p);
    case Scalar::f64: return detail::load_as_double<double>(p);
  }
  return 0.0;
}

}  // namespace adit::protocol
