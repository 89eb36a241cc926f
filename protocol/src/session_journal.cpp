// The session journal's record framing and payloads (session_journal.hpp).
#include "adit/protocol/session_journal.hpp"

#include <cstring>

#include <fmt/format.h>
#include <zlib.h>
#include <zstd.h>

namespace adit::protocol {
namespace {

template <typename T>
void put(std::vector<std::uint8_t>& out, const T& value) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
  out.insert(out.end(), p, p + sizeof(T));
}

// Reads values in order from a payload; fails (and stays failed) past its end.
class Cursor {
 public:
  explicit Cursor(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  template <typename T>
  bool get(T& value) {
    if (!ok_ || bytes_.size() - at_ < sizeof(T)) return ok_ = false;
    std::memcpy(&value, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return true;
  }
  std::span<const std::uint8_t> rest() const { return bytes_.subspan(at_); }
  bool ok() const { return ok_; }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
  bool ok_ = true;
};

std::uint32_t crc_of(std::span<const std::uint8_t> head, std::span<const std::uint8_t> payload) {
  uLong crc = crc32(0L, Z_NULL, 0);
  crc = crc32(crc, head.data(), static_cast<uInt>(head.size()));
  // zlib's length is 32-bit: payloads are below kJournalMaxPayload. An empty
  // payload adds nothing (and zlib would take a null pointer for "start over").
  if (!payload.empty()) crc = crc32(crc, payload.data(), static_cast<uInt>(payload.size()));
  return static_cast<std::uint32_t>(crc);
}

void put_pose(std::vector<std::uint8_t>& out, const JournalPose& pose) {
  put(out, pose.stamp_ns);
  for (double v : pose.position) put(out, v);
  for (double v : pose.orientation) put(out, v);
}

bool get_pose(Cursor& in, JournalPose& pose) {
  in.get(pose.stamp_ns);
  for (double& v : pose.position) in.get(v);
  for (double& v : pose.orientation) in.get(v);
  return in.ok();
}

// zstd of `raw` appended to `out` (level 1: the journal thread keeps up with
// a 128-beam sensor's map growth on one slow core).
void put_compressed(std::vector<std::uint8_t>& out, std::span<const std::uint8_t> raw) {
  const std::size_t at = out.size();
  out.resize(at + ZSTD_compressBound(raw.size()));
  const std::size_t n = ZSTD_compress(out.data() + at, out.size() - at, raw.data(), raw.size(), 1);
  if (ZSTD_isError(n)) throw std::runtime_error(fmt::format("journal: zstd: {}", ZSTD_getErrorName(n)));
  out.resize(at + n);
}

// Decompresses exactly `size` bytes from `in`; false when it does not hold them.
bool get_compressed(std::span<const std::uint8_t> in, std::size_t size, std::vector<std::uint8_t>& raw) {
  const unsigned long long announced = ZSTD_getFrameContentSize(in.data(), in.size());
  if (announced != size) return false;
  raw.resize(size);
  const std::size_t n = ZSTD_decompress(raw.data(), raw.size(), in.data(), in.size());
  return !ZSTD_isError(n) && n == size;
}

constexpr std::size_t kTilePointBytes = 3 * sizeof(double) + sizeof(float) + sizeof(double);
constexpr std::size_t kKeyframePointBytes = 3 * sizeof(float);
constexpr std::uint32_t kMaxPoints = kJournalMaxPayload / kKeyframePointBytes;

}  // namespace

void append_journal_record(std::vector<std::uint8_t>& out, JournalRecordType type,
                           std::span<const std::uint8_t> payload) {
  if (payload.size() > kJournalMaxPayload)
    throw std::length_error(fmt::format("journal: a record of {} bytes exceeds {}", payload.size(), kJournalMaxPayload));
  const std::size_t at = out.size();
  put(out, kJournalMagic);
  put(out, static_cast<std::uint8_t>(type));
  put(out, std::uint8_t{0});
  put(out, std::uint16_t{0});
  put(out, static_cast<std::uint32_t>(payload.size()));
  const std::uint32_t crc = crc_of(std::span(out).subspan(at + 4, 8), payload);
  put(out, crc);
  out.insert(out.end(), payload.begin(), payload.end());
}

void encode_journal_pose(const JournalPose& pose, std::vector<std::uint8_t>& out) { put_pose(out, pose); }

void encode_journal_tile_points(const JournalTilePoints& tile, std::vector<std::uint8_t>& out) {
  for (std::int32_t v : tile.tile) put(out, v);
  put(out, static_cast<std::uint32_t>(tile.points.size()));
  std::vector<std::uint8_t> raw;
  raw.reserve(tile.points.size() * kTilePointBytes);
  for (const MapPoint& p : tile.points) {
    put(raw, p.x);
    put(raw, p.y);
    put(raw, p.z);
    put(raw, p.intensity);
    put(raw, p.time);
  }
  put_compressed(out, raw);
}

void encode_journal_keyframe(const JournalKeyframe& keyframe, std::vector<std::uint8_t>& out) {
  put_pose(out, keyframe.pose);
  put(out, static_cast<std::uint32_t>(keyframe.points.size()));
  std::vector<std::uint8_t> raw;
  raw.reserve(keyframe.points.size() * kKeyframePointBytes);
  for (const std::array<float, 3>& p : keyframe.points)
    for (float v : p) put(raw, v);
  put_compressed(out, raw);
}

bool decode_journal_pose(std::span<const std::uint8_t> payload, JournalPose& out) {
  Cursor in(payload);
  return get_pose(in, out) && in.rest().empty();
}

bool peek_journal_tile_points(std::span<const std::uint8_t> payload, std::array<std::int32_t, 3>& tile,
                              std::uint32_t& count) {
  Cursor in(payload);
  for (std::int32_t& v : tile) in.get(v);
  in.get(count);
  return in.ok() && count <= kMaxPoints;
}

bool decode_journal_tile_points(std::span<const std::uint8_t> payload, JournalTilePoints& out) {
  std::uint32_t n = 0;
  if (!peek_journal_tile_points(payload, out.tile, n)) return false;
  std::vector<std::uint8_t> raw;
  if (!get_compressed(payload.subspan(16), std::size_t{n} * kTilePointBytes, raw)) return false;
  out.points.resize(n);
  Cursor in(raw);
  for (MapPoint& p : out.points) {
    in.get(p.x);
    in.get(p.y);
    in.get(p.z);
    in.get(p.intensity);
    in.get(p.time);
  }
  return in.ok();
}

bool decode_journal_keyframe(std::span<const std::uint8_t> payload, JournalKeyframe& out) {
  Cursor in(payload);
  std::uint32_t n = 0;
  if (!get_pose(in, out.pose) || !in.get(n) || n > kMaxPoints) return false;
  std::vector<std::uint8_t> raw;
  if (!get_compressed(in.rest(), std::size_t{n} * kKeyframePointBytes, raw)) return false;
  out.points.resize(n);
  Cursor points(raw);
  for (std::array<float, 3>& p : out.points)
    for (float& v : p) points.get(v);
  return points.ok();
}

std::optional<JournalReader::Record> JournalReader::next() {
  const std::size_t left = bytes_.size() - offset_;
  if (left == 0) return std::nullopt;
  if (left < kJournalRecordHeader) {
    reason_ = fmt::format("a record header cut short at byte {}", offset_);
    return std::nullopt;
  }
  Cursor head(bytes_.subspan(offset_, kJournalRecordHeader));
  std::uint32_t magic = 0, size = 0, crc = 0;
  std::uint8_t type = 0;
  head.get(magic);
  head.get(type);
  if (magic != kJournalMagic) {
    reason_ = fmt::format("no record starts at byte {}", offset_);
    return std::nullopt;
  }
  std::uint8_t reserved8 = 0;
  std::uint16_t reserved16 = 0;
  head.get(reserved8);
  head.get(reserved16);
  head.get(size);
  head.get(crc);
  if (size > kJournalMaxPayload || size > left - kJournalRecordHeader) {
    reason_ = fmt::format("the record at byte {} announces {} bytes, {} are there", offset_, size,
                          left - kJournalRecordHeader);
    return std::nullopt;
  }
  const std::span<const std::uint8_t> payload = bytes_.subspan(offset_ + kJournalRecordHeader, size);
  if (crc_of(bytes_.subspan(offset_ + 4, 8), payload) != crc) {
    reason_ = fmt::format("the record at byte {} fails its checksum", offset_);
    return std::nullopt;
  }
  Record record{static_cast<JournalRecordType>(type), offset_, payload};
  offset_ += kJournalRecordHeader + size;
  return record;
}

}  // namespace adit::protocol
