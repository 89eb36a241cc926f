#pragma once
// The session journal: what mapping produces, appended to <session>/journal.adj
// as it happens, so that a session survives a crash or a pulled battery
// (docs/SESSIONS.md). Append-only records, each framed and checksummed:
//
//   offset 0   u32 magic 0x314A4441 ("ADJ1" little-endian)
//          4   u8  record type (JournalRecordType)
//          5   u8  0 (reserved)   6 u16 0 (reserved)
//          8   u32 payload size (≤ kJournalMaxPayload)
//         12   u32 CRC-32 (ISO-HDLC, zlib's) of bytes 4..11 and the payload
//         16   payload
//
// A reader stops at the first record that does not frame or check: what
// follows it is the torn tail a crash leaves (a record half written, or a
// page the disk never got), cut and counted, never decoded. All integers and
// floats little-endian, as on every payload computer adit runs on.
//
// Payloads: header: UTF-8 JSON (session id, tile size, voxel); map pose:
// stamp_ns i64, position 3×f64, quaternion w,x,y,z 4×f64; tile points: tile
// x,y,z 3×i32, n u32, zstd of n × (x,y,z f64, intensity f32, time f64):
// the points a tile confirmed since the tile's previous record, lossless;
// keyframe: stamp_ns i64, pose as above, n u32, zstd of n × (x,y,z f32) in
// the keyframe's body frame; end: empty (the session finished cleanly).

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "adit/protocol/map_point.hpp"

namespace adit::protocol {

inline constexpr std::uint32_t kJournalMagic = 0x314A4441U;
inline constexpr std::size_t kJournalRecordHeader = 16;
inline constexpr std::uint32_t kJournalMaxPayload = 64U << 20U;  // a tile's delta is far below

enum class JournalRecordType : std::uint8_t { header = 1, map_pose = 2, tile_points = 3, keyframe = 4, end = 5 };

struct JournalPose {
  std::int64_t stamp_ns = 0;
  std::array<double, 3> position{0, 0, 0};
  std::array<double, 4> orientation{1, 0, 0, 0};  // w, x, y, z
};

struct JournalTilePoints {
  std::array<std::int32_t, 3> tile{0, 0, 0};
  std::vector<MapPoint> points;
};

struct JournalKeyframe {
  JournalPose pose;
  std::vector<std::array<float, 3>> points;  // body frame
};

// One framed record (header + payload) appended to `out`.
void append_journal_record(std::vector<std::uint8_t>& out, JournalRecordType type,
                           std::span<const std::uint8_t> payload);

// Payload encoders (append to `out`).
void encode_journal_pose(const JournalPose& pose, std::vector<std::uint8_t>& out);
void encode_journal_tile_points(const JournalTilePoints& tile, std::vector<std::uint8_t>& out);
void encode_journal_keyframe(const JournalKeyframe& keyframe, std::vector<std::uint8_t>& out);

// Payload decoders: false (and `out` unspecified) when the payload is malformed.
bool decode_journal_pose(std::span<const std::uint8_t> payload, JournalPose& out);
bool decode_journal_tile_points(std::span<const std::uint8_t> payload, JournalTilePoints& out);
// The tile and point count without decompressing (an index of a journal).
bool peek_journal_tile_points(std::span<const std::uint8_t> payload, std::array<std::int32_t, 3>& tile,
                              std::uint32_t& count);
bool decode_journal_keyframe(std::span<const std::uint8_t> payload, JournalKeyframe& out);

// Walks the records of a journal held in memory (a mapped or read file).
class JournalReader {
 public:
  explicit JournalReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}

  struct Record {
    JournalRecordType type;
    std::size_t offset;  // of the record's header
    std::span<const std::uint8_t> payload;
  };
  // The next good record, or nothing at the end or at the first bad one.
  std::optional<Record> next();
  // Bytes of whole, checked records read so far.
  std::size_t good_bytes() const { return offset_; }
  // After next() returned nothing: why the rest was not read ("" at a clean end).
  const std::string& stop_reason() const { return reason_; }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t offset_ = 0;
  std::string reason_;
};

}  // namespace adit::protocol
