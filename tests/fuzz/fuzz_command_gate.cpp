// Fuzzes command decoding and validation: any bytes on ADIT/<id>/COMMAND must
// be classified (execute, replay, reject, malformed) without a crash.

#include <cstddef>
#include <cstdint>

#include "adit/protocol/command_gate.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  adit::protocol::CommandGate gate("rig1", 4);
  for (int pass = 0; pass < 2; ++pass) {  // the second pass exercises replays
    const auto r = gate.inspect(data, size);
    if (r.kind == adit::protocol::GateResult::Kind::execute || r.kind == adit::protocol::GateResult::Kind::reject) {
      adit::command_ack_t ack;
      ack.request_id = r.command.request_id;
      gate.remember(ack);
    }
  }
  return 0;
}
