#pragma once
// LCM channel names: ADIT/<payload-id>/<KIND>, so several payloads share one
// network and a client picks one by id. LCM limits channel names to 63 bytes.

#include <cstddef>
#include <string>
#include <string_view>

namespace adit::protocol {

enum class Channel { pose, status, command, ack, tile_index, tile, tile_request, file_request, file, imu_pose, grid, frame, graph_path,
                     loops };
inline constexpr int kChannelCount = 14;

// Longest suffix "/TILE_REQUEST" plus "ADIT/" leaves 45 bytes; 32 is plenty.
inline constexpr std::size_t kMaxPayloadIdLength = 32;
// Every encoded message stays below this (one UDP datagram after LCM's header
// when fragmented by LCM, and a bounded burst on a flaky Wi-Fi link).
inline constexpr std::size_t kMaxMessageBytes = 60 * 1024;
// ttl=1 reaches the tablet's network; tests use ttl=0 (this host only).
inline constexpr std::string_view kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=1";

// "" when `id` is a usable payload id (1..32 of [A-Za-z0-9_-]), else why not.
std::string payload_id_problem(std::string_view id);

std::string_view channel_kind(Channel channel);
// `payload_id` must be valid (checked by the caller with payload_id_problem).
std::string channel_name(std::string_view payload_id, Channel channel);

}  // namespace adit::protocol
