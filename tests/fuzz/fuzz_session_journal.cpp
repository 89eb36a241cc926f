// Fuzzes the session journal's reader and payload decoders: any bytes in a
// journal.adj (a torn or damaged file after a crash) must be read up to the
// first bad record and decoded or refused, without a crash.

#include <cstddef>
#include <cstdint>
#include <span>

#include "adit/protocol/session_journal.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace adit::protocol;
  JournalReader reader(std::span(data, size));
  JournalPose pose;
  JournalTilePoints tile;
  JournalKeyframe keyframe;
  while (const auto record = reader.next()) {
    // Every decoder on every payload: a record's type is data too.
    decode_journal_pose(record->payload, pose);
    decode_journal_tile_points(record->payload, tile);
    decode_journal_keyframe(record->payload, keyframe);
  }
  // The payload decoders on raw bytes too (a record whose checksum held by chance).
  decode_journal_tile_points(std::span(data, size), tile);
  decode_journal_keyframe(std::span(data, size), keyframe);
  return 0;
}
