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
  return std::nullopt;
}

std::string_view verb_name(Verb verb) {
  switch (verb) {
    case Verb::start: return "START";
    case Verb::stop: return "STOP";
    case Verb::export_map: return "EXPORT";
    case Verb::ping: return "PING";
    case Verb::sessions: return "SESSIONS";
  }
  return "UNKNOWN";
}

CommandGate::CommandGate(std::string payload_id, std::size_t window)
    : payload_id_(std::move(payload_id)), window_(window == 0 ? 1 : window) {}

GateResult CommandGate::inspect(const void* data, std::size_t size) {
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
  if (const auto seen = answers_.find(c.request_id); seen != answers_.end()) {
    ++counts_.replayed;
    result.kind = GateResult::Kind::replay;
    result.previous = seen->second;
    result.reason = "replayed request id: answered again, not executed";
    return result;
  }
  result.kind = GateResult::Kind::reject;
  ++counts_.rejected;
  if (c.schema < 1) {
    result.reason = fmt::format("schema {} is not supported", c.schema);
  } else if (c.payload_id != payload_id_) {
    result.reason = fmt::format("addressed to payload '{}', this is '{}'", c.payload_id, payload_id_);
  } else if (const auto verb = parse_verb(c.verb); !verb) {
    result.reason = fmt::format("unknown verb '{}' (known: START, STOP, EXPORT, PING, SESSIONS)", c.verb);
  } else if (c.auth_size != 0) {
    result.reason = "authentication is not supported yet; send an empty auth field";
  } else {
    --counts_.rejected;
    ++counts_.passed;
    result.kind = GateResult::Kind::execute;
    result.verb = *verb;
    result.reason.clear();
  }
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
