#include "adit/protocol/session_state.hpp"

namespace adit::protocol {

std::string_view state_name(SessionState state) {
  switch (state) {
    case SessionState::idle: return "IDLE";
    case SessionState::mapping: return "MAPPING";
    case SessionState::stopping: return "STOPPING";
  }
  return "UNKNOWN";
}

Transition next_state(SessionState state, SessionEvent event) {
  const auto accept = [state](SessionState to, std::string reason) { return Transition{true, state, to, std::move(reason)}; };
  const auto reject = [state](std::string reason) { return Transition{false, state, state, std::move(reason)}; };
  switch (event) {
    case SessionEvent::start:
      if (state == SessionState::idle) return accept(SessionState::mapping, "mapping started");
      if (state == SessionState::mapping) return reject("already mapping");
      return reject("still stopping the last session");
    case SessionEvent::stop:
      if (state == SessionState::mapping) return accept(SessionState::stopping, "stopping: flushing the session");
      if (state == SessionState::stopping) return reject("already stopping");
      return reject("not mapping");
    case SessionEvent::stopped:
      if (state == SessionState::stopping) return accept(SessionState::idle, "session stopped");
      return reject("no stop in progress");
  }
  return reject("unknown event");
}

}  // namespace adit::protocol
