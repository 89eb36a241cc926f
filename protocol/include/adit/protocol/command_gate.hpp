#pragma once
// Validation of incoming commands before anything is executed: decoding,
// target payload, verb, and de-duplication by request id. Clients retry with
// the same request id, so a replayed id within the window gets the same ack
// again and is not executed twice. Nothing here touches sockets.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>

#include "adit/command_ack_t.hpp"
#include "adit/command_t.hpp"

namespace adit::protocol {

enum class Verb { start, stop, export_map, ping, sessions };
std::optional<Verb> parse_verb(std::string_view text);
std::string_view verb_name(Verb verb);

struct GateCounts {
  std::size_t malformed = 0, rejected = 0, replayed = 0, passed = 0;
};

struct GateResult {
  enum class Kind {
    execute,   // new and valid: run `verb`, then remember() the ack
    replay,    // seen before: send `previous` again
    reject,    // answer with an ack carrying `reason`
    malformed  // not a command: counted, no answer (no request id to answer)
  };
  Kind kind = Kind::malformed;
  Verb verb = Verb::ping;
  command_t command;
  command_ack_t previous;
  std::string reason;
};

class CommandGate {
 public:
  // `window`: how many request ids are remembered (oldest forgotten first).
  explicit CommandGate(std::string payload_id, std::size_t window = 1024);

  // Decodes and classifies one LCM message body.
  GateResult inspect(const void* data, std::size_t size);
  // Stores the answer to a request id so a replay gets it again.
  void remember(const command_ack_t& ack);
  const GateCounts& counts() const { return counts_; }

 private:
  std::string payload_id_;
  std::size_t window_;
  std::deque<std::int64_t> order_;
  std::unordered_map<std::int64_t, command_ack_t> answers_;
  GateCounts counts_;
};

}  // namespace adit::protocol
