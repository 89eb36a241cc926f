#include "adit/drivers/lidar/decoder.hpp"

namespace adit::drivers {

std::string_view to_string(PacketStatus status) {
  switch (status) {
    case PacketStatus::ok: return "ok";
    case PacketStatus::auxiliary: return "auxiliary";
    case PacketStatus::foreign: return "foreign";
    case PacketStatus::truncated: return "truncated";
    case PacketStatus::malformed: return "malformed";
  }
  return "unknown";
}

}  // namespace adit::drivers
