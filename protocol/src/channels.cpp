#include "adit/protocol/channels.hpp"

#include <fmt/format.h>

namespace adit::protocol {

std::string payload_id_problem(std::string_view id) {
  if (id.empty()) return "payload id is empty";
  if (id.size() > kMaxPayloadIdLength) return fmt::format("payload id is longer than {} characters", kMaxPayloadIdLength);
  for (const char c : id) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    if (!ok) return fmt::format("payload id '{}' may only use letters, digits, '_' and '-'", id);
  }
  return {};
}

std::string_view channel_kind(Channel channel) {
  switch (channel) {
    case Channel::pose: return "POSE";
    case Channel::status: return "STATUS";
    case Channel::command: return "COMMAND";
    case Channel::ack: return "ACK";
    case Channel::tile_index: return "TILE_INDEX";
    case Channel::tile: return "TILE";
    case Channel::tile_request: return "TILE_REQUEST";
    case Channel::file_request: return "FILE_REQUEST";
    case Channel::file: return "FILE";
    case Channel::imu_pose: return "POSE_IMU";
    case Channel::grid: return "GRID";
    case Channel::frame: return "FRAME";
    case Channel::graph_path: return "GRAPH_PATH";
    case Channel::loops: return "LOOPS";
  }
  return "UNKNOWN";
}

std::string channel_name(std::string_view payload_id, Channel channel) {
  return fmt::format("ADIT/{}/{}", payload_id, channel_kind(channel));
}

}  // namespace adit::protocol
