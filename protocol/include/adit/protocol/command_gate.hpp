#pragma once
// Validation of incoming commands before anything is executed: decoding,
// authentication (when the payload holds keys: command_auth.hpp), target
// payload, freshness, verb, and de-duplication by request id. Clients retry
// with the same request id, so a replayed id within the window gets the same
// ack again and is not executed twice. Nothing here touches sockets or clocks
// (the caller passes the time).

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "adit/command_ack_t.hpp"
#include "adit/command_t.hpp"
#include "adit/protocol/command_auth.hpp"

namespace adit::protocol {

enum class Verb { start, stop, export_map, ping, sessions, hint };
std::optional<Verb> parse_verb(std::string_view text);
std::string_view verb_name(Verb verb);

struct GateCounts {
  std::size_t malformed = 0, rejected = 0, replayed = 0, passed = 0;
  // Rejections by reason (each also counted in `rejected`). The first four
  // happen only while the payload holds keys.
  std::size_t unsigned_commands = 0;  // no tag
  std::size_t bad_tag = 0;            // malformed tag, unknown key or wrong tag
  std::size_t stale = 0;              // signed time outside the window
  std::size_t replay_rejected = 0;    // a signed command executed before, its answer forgotten
  std::size_t other_payload = 0;      // addressed to another payload id
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
  // False for a command that failed authentication: its answer must not be
  // remembered, or anyone could flush the memory of real commands' answers.
  bool remember = true;
};

class CommandGate {
 public:
  // `window`: how many request ids are remembered (oldest forgotten first).
  explicit CommandGate(std::string payload_id, std::size_t window = 1024);

  // Requires every command to be signed by one of `keys` with a time within
  // `window_us` of the payload's clock. No keys: commands are not
  // authenticated (a signed command is accepted without checking its tag).
  void set_keys(std::vector<CommandKey> keys, std::int64_t window_us);
  bool requires_auth() const { return !keys_.empty(); }
  std::int64_t window_us() const { return window_us_; }

  // Decodes and classifies one LCM message body; `now_us` is the payload's
  // wall clock (µs since the Unix epoch), against which freshness is judged.
  GateResult inspect(const void* data, std::size_t size, std::int64_t now_us);
  // Stores the answer to a request id so a replay gets it again.
  void remember(const command_ack_t& ack);
  const GateCounts& counts() const { return counts_; }

 private:
  void reject(GateResult& result, std::size_t* reason_count, std::string reason);

  std::string payload_id_;
  std::size_t window_;
  std::deque<std::int64_t> order_;
  std::unordered_map<std::int64_t, command_ack_t> answers_;
  std::vector<CommandKey> keys_;
  std::int64_t window_us_ = 30'000'000;
  // Signed commands executed within the time window: request id -> signed
  // time. Only authenticated commands enter, so nobody can flush it.
  std::unordered_map<std::int64_t, std::int64_t> executed_;
  GateCounts counts_;
};

}  // namespace adit::protocol
