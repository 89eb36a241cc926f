#include "adit/protocol/tile_assembler.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "adit/protocol/tile_codec.hpp"
#include "adit/tile_segment_t.hpp"

namespace adit::protocol {

void TileAssembler::note_index(std::int64_t id, std::int32_t version, std::int32_t n_segments) {
  if (version < 1 || n_segments < 1 || n_segments > kMaxSegmentsPerTile) return;
  Tile& tile = tiles_[id];
  if (version > tile.wanted_version) {
    tile.wanted_version = version;
    tile.wanted_segments = n_segments;
  }
}

SegmentOutcome TileAssembler::count(SegmentOutcome outcome) {
  switch (outcome) {
    case SegmentOutcome::stored: ++counts_.stored; break;
    case SegmentOutcome::completed: ++counts_.completed; break;
    case SegmentOutcome::duplicate: ++counts_.duplicate; break;
    case SegmentOutcome::stale: ++counts_.stale; break;
    case SegmentOutcome::malformed: ++counts_.malformed; break;
    case SegmentOutcome::corrupt: ++counts_.corrupt; break;
  }
  return outcome;
}

SegmentOutcome TileAssembler::add_segment(const tile_segment_t& m) {
  const bool shape_ok = m.version >= 1 && m.base_version >= 0 && m.base_version < m.version && m.n_segments >= 1 &&
                        m.n_segments <= kMaxSegmentsPerTile && m.segment >= 0 && m.segment < m.n_segments &&
                        m.first_segment >= 0 && m.first_segment <= m.n_segments &&
                        (m.base_version > 0 || m.first_segment == 0) && m.n_points >= 0 &&
                        static_cast<std::uint32_t>(m.n_points) <= kMaxTilePoints && m.size > 0 &&
                        static_cast<std::size_t>(m.size) == m.data.size() && m.data.size() <= kChunkPayloadBytes;
  if (!shape_ok) {
    last_error_ = fmt::format("tile {} version {} segment {}/{} (base {}, first {}) of {} bytes is malformed",
                              m.tile_id, m.version, m.segment, m.n_segments, m.base_version, m.first_segment, m.size);
    return count(SegmentOutcome::malformed);
  }
  const bool centred = m.schema >= 3;  // the segment's origin (tile_codec.hpp)
  Tile& tile = tiles_[m.tile_id];
  if (m.version <= tile.done_version || m.version < tile.pending_version) return count(SegmentOutcome::stale);
  if (m.version > tile.wanted_version) {  // the live stream ran ahead of the index
    tile.wanted_version = m.version;
    tile.wanted_segments = m.n_segments;
  }
  if (m.version > tile.pending_version) {
    // Segments of the partial version below first_segment did not change
    // since (base_version <= it): they are kept, so a slow link downloading
    // a tile that keeps growing is not sent back to the start every second.
    const std::size_t keep = tile.pending_version > 0 && m.base_version <= tile.pending_version
                                 ? std::min(tile.parts.size(), static_cast<std::size_t>(m.first_segment))
                                 : 0;
    tile.pending_version = m.version;
    tile.pending_first = -1;
    tile.parts.resize(keep);
    tile.have.resize(keep);
    tile.parts.resize(static_cast<std::size_t>(m.n_segments));
    tile.have.resize(static_cast<std::size_t>(m.n_segments), false);
  }
  if (static_cast<std::size_t>(m.n_segments) != tile.parts.size()) {
    last_error_ = fmt::format("tile {} version {} changed its segment count", m.tile_id, m.version);
    return count(SegmentOutcome::malformed);
  }
  // Segments below first_segment did not change after base_version; holding
  // a version at least that new, we have them. Of several such bases the
  // largest first segment is the tightest (each is a valid bound).
  if (m.base_version <= tile.done_version && static_cast<std::size_t>(m.first_segment) <= tile.segments.size())
    tile.pending_first = std::max(tile.pending_first, m.first_segment);
  const auto index = static_cast<std::size_t>(m.segment);
  if (tile.have[index]) return count(finish_if_complete(tile) == SegmentOutcome::completed ? SegmentOutcome::completed
                                                                                          : SegmentOutcome::duplicate);
  scratch_.clear();
  if (const std::string error = decode_segment(m.data, tile_key(m.tile_id), m.tile_size_m, m.quantum_m, centred, scratch_);
      !error.empty()) {
    // Not kept: it is asked for again (a datagram damaged on the way is
    // likely; a daemon serving bad bytes shows as this error repeating).
    last_error_ = fmt::format("tile {} version {} segment {}: {}", m.tile_id, m.version, m.segment, error);
    return count(SegmentOutcome::corrupt);
  }
  HeldSegment& held = tile.parts[index];
  held = HeldSegment{{}, spill_ ? spill_->write(m.data) : nullptr, static_cast<std::uint32_t>(scratch_.size()),
                     m.tile_id, m.tile_size_m, m.quantum_m, centred, m.utime};
  if (!held.spilled) held.frame.assign(m.data.begin(), m.data.end());
  tile.have[index] = true;
  return count(finish_if_complete(tile));
}

SegmentOutcome TileAssembler::finish_if_complete(Tile& tile) {
  if (tile.pending_first < 0) return SegmentOutcome::stored;
  const auto first = static_cast<std::size_t>(tile.pending_first);
  for (std::size_t i = first; i < tile.have.size(); ++i)
    if (!tile.have[i]) return SegmentOutcome::stored;
  tile.segments.resize(tile.parts.size());  // the held ones below `first` stay
  for (std::size_t i = first; i < tile.parts.size(); ++i) tile.segments[i] = std::move(tile.parts[i]);
  tile.done_version = tile.pending_version;
  tile.replaced_from = tile.pending_first;
  tile.pending_version = 0;
  tile.pending_first = -1;
  tile.parts.clear();
  tile.have.clear();
  return SegmentOutcome::completed;
}

std::vector<MissingSegment> TileAssembler::missing(std::size_t limit) const {
  std::vector<MissingSegment> out;
  for (const auto& [id, tile] : tiles_) {
    if (tile.wanted_version <= tile.done_version) continue;
    if (tile.pending_version != tile.wanted_version || tile.pending_first < 0) {
      if (out.size() >= limit) return out;
      out.push_back({id, tile.done_version, -1});
      continue;
    }
    for (std::size_t i = static_cast<std::size_t>(tile.pending_first); i < tile.have.size(); ++i) {
      if (tile.have[i]) continue;
      if (out.size() >= limit) return out;
      out.push_back({id, tile.done_version, static_cast<std::int32_t>(i)});
    }
  }
  return out;
}

bool TileAssembler::complete() const {
  for (const auto& [id, tile] : tiles_)
    if (tile.wanted_version > tile.done_version) return false;
  return true;
}

std::size_t TileAssembler::segments_wanted() const {
  std::size_t n = 0;
  for (const auto& [id, tile] : tiles_) n += static_cast<std::size_t>(tile.wanted_segments);
  return n;
}

std::size_t TileAssembler::segments_have() const {
  std::size_t n = 0;
  for (const auto& [id, tile] : tiles_) {
    if (tile.done_version >= tile.wanted_version) {
      n += static_cast<std::size_t>(tile.wanted_segments);
    } else if (tile.pending_version == tile.wanted_version) {
      const std::size_t first = tile.pending_first < 0 ? 0 : static_cast<std::size_t>(tile.pending_first);
      n += first + static_cast<std::size_t>(std::count(tile.have.begin() + static_cast<std::ptrdiff_t>(first),
                                                        tile.have.end(), true));
    }
  }
  return n;
}

std::optional<TileAssembler::HeldTile> TileAssembler::held(std::int64_t id) const {
  const auto it = tiles_.find(id);
  if (it == tiles_.end() || it->second.done_version == 0) return std::nullopt;
  const Tile& tile = it->second;
  return HeldTile{tile.done_version, tile.replaced_from, tile.segments};
}

std::vector<MapPoint> TileAssembler::points() const {
  std::size_t n = 0;
  for (const auto& [id, tile] : tiles_)
    for (const auto& segment : tile.segments) n += segment.points;
  std::vector<MapPoint> out;
  out.reserve(n);
  for (const auto& [id, tile] : tiles_)
    for (const auto& segment : tile.segments) segment.decode_into(out);
  return out;
}

std::size_t TileAssembler::HeldTile::points() const {
  std::size_t n = 0;
  for (const HeldSegment& s : segments) n += s.points;
  return n;
}

void HeldSegment::decode_into(std::vector<MapPoint>& out) const {
  const std::size_t first = out.size();
  std::vector<std::uint8_t> read;  // a spilled frame's bytes (one allocation a segment, not a point)
  if (spilled && !spilled->read(read)) read.clear();
  const std::span<const std::uint8_t> bytes = spilled ? std::span<const std::uint8_t>(read) : frame;
  // Decoded once already, on arrival: an error here is not expected (the frame is unchanged since).
  if (bytes.empty() || !decode_segment(bytes, tile_key(tile_id), tile_size_m, quantum_m, centred, out).empty()) {
    out.resize(first);
    return;
  }
  for (std::size_t i = first; i < out.size(); ++i) out[i].time = static_cast<double>(utime) * 1e-6;
}

}  // namespace adit::protocol
