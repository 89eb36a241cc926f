#pragma once
// Decoding of network bytes into LCM types without trusting them. The code
// lcm-gen 1.3 emits resizes arrays to the count found in the message before
// checking that the bytes are there, and a string length of 0 or less makes
// it throw: a 30-byte datagram can ask for gigabytes. So the bytes are first
// walked against the type's layout (counts and string lengths must fit what
// remains), then decoded. Found by fuzz_command_gate.

#include <cstddef>
#include <cstdint>
#include <exception>
#include <span>

#include "adit/command_ack_t.hpp"
#include "adit/command_t.hpp"
#include "adit/file_chunk_t.hpp"
#include "adit/file_request_t.hpp"
#include "adit/frame_t.hpp"
#include "adit/graph_path_t.hpp"
#include "adit/grid_patch_t.hpp"
#include "adit/loop_status_t.hpp"
#include "adit/pose_t.hpp"
#include "adit/status_t.hpp"
#include "adit/tile_segment_t.hpp"
#include "adit/tile_index_t.hpp"
#include "adit/tile_request_t.hpp"

namespace adit::protocol {

// Layout of each received type (must follow protocol/lcm/*.lcm; the tests
// check it against encoded messages).
enum class LcmType { pose, status, command, command_ack, tile_index, tile_segment, tile_request, file_request, file_chunk,
                     grid_patch, frame, graph_path, loop_status };

// True when `bytes` (hash included) has exactly the layout of `type`.
bool lcm_layout_ok(LcmType type, std::span<const std::uint8_t> bytes);

inline constexpr LcmType lcm_type_of(const pose_t*) { return LcmType::pose; }
inline constexpr LcmType lcm_type_of(const status_t*) { return LcmType::status; }
inline constexpr LcmType lcm_type_of(const command_t*) { return LcmType::command; }
inline constexpr LcmType lcm_type_of(const command_ack_t*) { return LcmType::command_ack; }
inline constexpr LcmType lcm_type_of(const tile_index_t*) { return LcmType::tile_index; }
inline constexpr LcmType lcm_type_of(const tile_segment_t*) { return LcmType::tile_segment; }
inline constexpr LcmType lcm_type_of(const tile_request_t*) { return LcmType::tile_request; }
inline constexpr LcmType lcm_type_of(const file_request_t*) { return LcmType::file_request; }
inline constexpr LcmType lcm_type_of(const file_chunk_t*) { return LcmType::file_chunk; }
inline constexpr LcmType lcm_type_of(const grid_patch_t*) { return LcmType::grid_patch; }
inline constexpr LcmType lcm_type_of(const frame_t*) { return LcmType::frame; }
inline constexpr LcmType lcm_type_of(const graph_path_t*) { return LcmType::graph_path; }
inline constexpr LcmType lcm_type_of(const loop_status_t*) { return LcmType::loop_status; }

// Decodes `size` bytes into `out`; false (and `out` unspecified) for anything
// that is not exactly one well-formed `Message`.
template <typename Message>
bool checked_decode(const void* data, std::size_t size, Message& out) {
  constexpr std::size_t kLimit = 1u << 20;  // no adit message comes near this
  if (data == nullptr || size > kLimit) return false;
  const std::span bytes(static_cast<const std::uint8_t*>(data), size);
  if (!lcm_layout_ok(lcm_type_of(static_cast<const Message*>(nullptr)), bytes)) return false;
  try {
    return out.decode(data, 0, static_cast<int>(size)) == static_cast<int>(size);
  } catch (const std::exception&) {
    return false;  // defence in depth: the layout check should have caught it
  }
}

}  // namespace adit::protocol
