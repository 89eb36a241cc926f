// Fuzzes command decoding, authentication and validation: any bytes on
// ADIT/<id>/COMMAND must be classified (execute, replay, reject, malformed)
// without a crash, by a gate without keys and by one that requires a tag
// (decode, tag parse, HMAC verify, window, replay memory); what passes has its
// arguments parsed as HINT's (localise_hint.hpp), whatever its verb.

#include <array>
#include <cstddef>
#include <cstdint>

#include <cmath>
#include <cstdlib>
#include <string>

#include "adit/protocol/command_gate.hpp"
#include "adit/protocol/localise_hint.hpp"

namespace {

void exercise(adit::protocol::CommandGate& gate, const std::uint8_t* data, std::size_t size) {
  for (int pass = 0; pass < 2; ++pass) {  // the second pass exercises replays
    const auto r = gate.inspect(data, size, 1'795'000'000'000'000);
    if (r.kind == adit::protocol::GateResult::Kind::execute) {
      std::string error;
      const auto hint = adit::protocol::parse_localise_hint(r.command.args, error);
      if (hint && !(std::isfinite(hint->x_m) && std::isfinite(hint->y_m) && hint->radius_m >= 0.5)) std::abort();
      if (!hint && error.empty()) std::abort();  // a refusal names its reason
    }
    if ((r.kind == adit::protocol::GateResult::Kind::execute || r.kind == adit::protocol::GateResult::Kind::reject) &&
        r.remember) {
      adit::command_ack_t ack;
      ack.request_id = r.command.request_id;
      gate.remember(ack);
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  adit::protocol::CommandGate open_gate("rig1", 4);
  exercise(open_gate, data, size);
  std::array<std::uint8_t, adit::protocol::kCommandKeyBytes> secret{};
  secret.fill(7);  // the key of the signed seeds (tests/fuzz/seeds/protocol/signed_*.bin)
  adit::protocol::CommandGate keyed_gate("rig1", 4);
  keyed_gate.set_keys({adit::protocol::CommandKey(std::span<const std::uint8_t, 32>(secret))}, 30'000'000);
  exercise(keyed_gate, data, size);
  return 0;
}
