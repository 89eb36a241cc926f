#pragma once
// The receiving side of the tile stream: keeps each tile's segments at the
// newest version it holds complete, collects the segments of a newer version
// (only those changed since, tile_segment_t's base_version / first_segment),
// and says what is still missing (only that) so a client can ask for it with
// a tile_request_t: (tile, version held, segment or -1 for "every segment
// changed after the version I hold").
//
// Segments are held as they came: each zstd frame, checked by decoding it
// once on arrival and decoded again when asked for (about 5 bytes a point
// against 40 decoded), so a follower of a long session (adit console) holds
// the map at the stream's size; given a FrameSpill, on disk instead of in RAM.

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "adit/protocol/frame_spill.hpp"
#include "adit/protocol/map_point.hpp"

namespace adit {
class tile_segment_t;
}

namespace adit::protocol {

enum class SegmentOutcome { stored, completed, duplicate, stale, malformed, corrupt };

// One tile_request_t entry.
struct MissingSegment {
  std::int64_t tile_id = 0;
  std::int32_t held_version = 0;  // the version held complete; 0 = nothing
  std::int32_t segment = -1;      // -1: every segment changed after held_version
};

// One segment held: its frame as received and what decodes it.
struct HeldSegment {
  std::vector<std::uint8_t> frame;  // tile_codec's segment frame (zstd), unless spilled
  std::shared_ptr<const SpilledFrame> spilled;  // the frame on disk (shared by copies; freed with the last)
  std::uint32_t points = 0;
  std::int64_t tile_id = 0;
  double tile_size_m = 0.0;
  double quantum_m = 0.0;
  bool centred = true;     // schema 3: its origin (tile_codec.hpp)
  std::int64_t utime = 0;  // the segment message's: each point's time
  // Appends its points to `out` (checked on arrival: it decodes).
  void decode_into(std::vector<MapPoint>& out) const;
};

struct AssemblerCounts {
  std::size_t stored = 0, completed = 0, duplicate = 0, stale = 0, malformed = 0, corrupt = 0;
};

class TileAssembler {
 public:
  TileAssembler() = default;
  // Segments' frames written to `spill` (held in RAM when a write fails).
  explicit TileAssembler(std::shared_ptr<FrameSpill> spill) : spill_(std::move(spill)) {}

  // From the tile index: tile `id` exists at `version` in `n_segments` segments.
  void note_index(std::int64_t id, std::int32_t version, std::int32_t n_segments);

  SegmentOutcome add_segment(const tile_segment_t& segment);

  // What is lacking for every known tile to reach its newest known version,
  // at most `limit` entries; a tile whose lacking segments are not known yet
  // is one entry with segment -1.
  std::vector<MissingSegment> missing(std::size_t limit) const;
  bool complete() const;
  // Segments in hand and segments wanted, over the newest known versions (progress).
  std::size_t segments_have() const;
  std::size_t segments_wanted() const;

  // Every complete tile's points, in tile id order.
  std::vector<MapPoint> points() const;
  std::size_t tile_count() const { return tiles_.size(); }

  // One tile held complete: its version, its segments, and the first segment
  // its last completion replaced (the ones below it were held before), so a
  // follower of the stream can pass on only what changed (adit console).
  struct HeldTile {
    std::int32_t version = 0;
    std::int32_t replaced_from = 0;
    std::span<const HeldSegment> segments;
    std::size_t points() const;
  };
  // The tile `id` as held complete, or nullopt when none of it is.
  std::optional<HeldTile> held(std::int64_t id) const;
  const AssemblerCounts& counts() const { return counts_; }
  const std::string& last_error() const { return last_error_; }

 private:
  struct Tile {
    std::int32_t wanted_version = 0;
    std::int32_t wanted_segments = 0;
    std::int32_t done_version = 0;                // 0: nothing held yet
    std::vector<HeldSegment> segments;            // complete at done_version
    std::int32_t replaced_from = 0;               // the first segment the last completion replaced
    std::int32_t pending_version = 0;             // the version being collected, 0: none
    std::int32_t pending_first = -1;              // its first segment we lack, -1: not known yet
    std::vector<HeldSegment> parts;               // its segments received
    std::vector<bool> have;
  };
  SegmentOutcome finish_if_complete(Tile& tile);
  SegmentOutcome count(SegmentOutcome outcome);

  std::shared_ptr<FrameSpill> spill_;
  std::map<std::int64_t, Tile> tiles_;
  std::vector<MapPoint> scratch_;  // a segment decoded on arrival, to check it
  AssemblerCounts counts_;
  std::string last_error_;
};

}  // namespace adit::protocol
