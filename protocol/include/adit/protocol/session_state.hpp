#pragma once
// The session state machine: IDLE -> MAPPING -> STOPPING -> IDLE. A pure value
// type; the daemon drives it from tablet commands, the button and the end of
// its flush, and reports the result of every attempt.

#include <cstdint>
#include <string>
#include <string_view>

namespace adit::protocol {

// Values equal status_t.STATE_*.
enum class SessionState : std::int8_t { idle = 0, mapping = 1, stopping = 2 };
enum class SessionEvent { start, stop, stopped };

std::string_view state_name(SessionState state);

struct Transition {
  bool accepted = false;
  SessionState from = SessionState::idle;
  SessionState to = SessionState::idle;  // == from when rejected
  std::string reason;                    // why rejected, or what happened
};

// The transition `event` causes from `state`; rejected ones keep the state.
Transition next_state(SessionState state, SessionEvent event);

class SessionMachine {
 public:
  SessionState state() const { return state_; }
  Transition apply(SessionEvent event) {
    Transition t = next_state(state_, event);
    state_ = t.to;
    return t;
  }

 private:
  SessionState state_ = SessionState::idle;
};

}  // namespace adit::protocol
