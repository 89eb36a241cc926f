#include "adit/protocol/command_gate.hpp"

#include <fmt/format.h>

#include "adit/protocol/checked_decode.hpp"

namespace adit::protocol {

std::optional<Verb> parse_verb(std::string_view text) {
  if (text == "START") return Verb::start;
  if (text == "STOP") return Verb::stop;
  if (text == "EXPORT") return Verb::export_map;
  if (text == "PING") return Verb::ping;
  if (text == "SESSIONS") return Verb::sessions;
  if (text == "HINT") return Verb::hint;
  return std::nullopt;
}

std::string_view verb_name(Verb verb) {
  switch (verb) {
    case Verb::start: return "START";
    case Verb::stop: return "STOP";
    case Verb::export_map: return "EXPORT";
    case Verb::ping: return "PING";
    case Verb::sessions: return "SESSIONS";
    case Verb::hint: return "HINT";
  }
  return "UNKNOWN";
}

CommandGate::CommandGate(std::string payload_id, std::size_t window)
    : payload_id_(std::move(payload_id)), window_(window == 0 ? 1 : window) {}

void CommandGate::set_keys(std::vector<CommandKey> keys, std::int64_t window_us) {
  keys_ = std::move(keys);
  window_us_ = window_us > 0 ? window_us : 1;
}

void CommandGate::reject(GateResult& result, std::size_t* reason_count, std::string reason) {
  if (reason_count != nullptr) ++*reason_count;
  ++counts_.rejected;
  result.kind = GateResult::Kind::reject;
  result.reason = std::move(reason);
}

GateResult CommandGate::inspect(const void* data, std::size_t size, std::int64_t now_us) {
  GateResult result;
  if (!checked_decode(data, size, result.command)) {
    ++counts_.malformed;
    result.reason = fmt::format("{} bytes that are not an adit.command_t", size);
    return result;
  }
  const command_t& c = result.command;
  if (c.request_id == 0) {
    ++counts_.malformed;
    result.reason = "request id 0 is reserved";
    return result;
  }
  // Authentication first: a command that fails it learns nothing from the
  // answers remembered and leaves no trace in them.
  if (requires_auth()) {
    const AuthCheck check = verify_command(c, keys_);
    if (check.verdict != AuthVerdict::ok) {
      result.remember = false;
      switch (check.verdict) {
        case AuthVerdict::unsigned_command:
          reject(result, &counts_.unsigned_commands,
                 "unsigned: this payload accepts only signed commands (adit --key FILE)");
          break;
        case AuthVerdict::malformed:
          reject(result, &counts_.bad_tag,
                 fmt::format("bad tag: the auth field must be {} bytes of scheme 1 (HMAC-SHA-256)", kAuthBytes));
          break;
        case AuthVerdict::unknown_key:
          reject(result, &counts_.bad_tag,
                 fmt::format("bad tag: signed with key id {}, which this payload does not hold",
                             key_id_hex(check.key_id)));
          break;
        default:
          reject(result, &counts_.bad_tag, "bad tag: the tag does not match the command's content");
          break;
      }
      return result;
    }
  }
  if (const auto seen = answers_.find(c.request_id); seen != answers_.end()) {
    ++counts_.replayed;
    result.kind = GateResult::Kind::replay;
    result.previous = seen->second;
    result.reason = "replayed request id: answered again, not executed";
    return result;
  }
  if (c.schema < 1) {
    reject(result, nullptr, fmt::format("schema {} is not supported", c.schema));
    return result;
  }
  if (c.payload_id != payload_id_) {
    reject(result, &counts_.other_payload,
           fmt::format("other payload: addressed to payload '{}', this is '{}'", c.payload_id, payload_id_));
    return result;
  }
  if (requires_auth()) {
    const std::int64_t skew = c.utime - now_us;
    if (skew > window_us_ || skew < -window_us_) {
      reject(result, &counts_.stale,
             fmt::format("stale: signed at {} µs, {:+.1f} s from this payload's clock ({} µs); the window is ±{:.0f} s",
                         c.utime, 1e-6 * static_cast<double>(skew), now_us, 1e-6 * static_cast<double>(window_us_)));
      return result;
    }
    if (executed_.count(c.request_id) != 0) {
      reject(result, &counts_.replay_rejected, "replayed: this signed request id was executed before");
      return result;
    }
  }
  const auto verb = parse_verb(c.verb);
  if (!verb) {
    reject(result, nullptr, fmt::format("unknown verb '{}' (known: START, STOP, EXPORT, PING, SESSIONS)", c.verb));
    return result;
  }
  if (requires_auth()) {
    // Forget what the window no longer lets through anyway (rare: only
    // authenticated commands are here).
    std::erase_if(executed_, [&](const auto& entry) { return entry.second < now_us - window_us_; });
    executed_.emplace(c.request_id, c.utime);
  }
  ++counts_.passed;
  result.kind = GateResult::Kind::execute;
  result.verb = *verb;
  result.reason.clear();
  return result;
}

void CommandGate::remember(const command_ack_t& ack) {
  if (answers_.emplace(ack.request_id, ack).second) order_.push_back(ack.request_id);
  while (order_.size() > window_) {
    answers_.erase(order_.front());
    order_.pop_front();
  }
}

}  // namespace adit::protocol
