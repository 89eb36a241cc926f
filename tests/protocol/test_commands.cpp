// Command validation, replay de-duplication and the session state machine.
#include <gtest/gtest.h>

#include <vector>

#include "adit/protocol/command_gate.hpp"
#include "adit/protocol/localise_hint.hpp"
#include "adit/protocol/session_state.hpp"

namespace adit::protocol {
namespace {

std::vector<std::uint8_t> encoded(const command_t& c) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(c.getEncodedSize()));
  c.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

command_t make(std::int64_t id, std::string verb, std::string payload = "rig1") {
  command_t c;
  c.schema = 1;
  c.request_id = id;
  c.payload_id = std::move(payload);
  c.verb = std::move(verb);
  c.n_args = 0;  // LCM types leave numbers uninitialised
  c.auth_size = 0;
  return c;
}

constexpr std::int64_t kNow = 1'795'000'000'000'000;  // the payload's clock in these tests (µs)

GateResult inspect(CommandGate& gate, const command_t& c) {
  const auto bytes = encoded(c);
  return gate.inspect(bytes.data(), bytes.size(), kNow);
}

TEST(CommandGate, PassesKnownVerbsForThisPayload) {
  CommandGate gate("rig1");
  for (const char* verb : {"START", "STOP", "EXPORT", "PING", "SESSIONS", "HINT"}) {
    const auto r = inspect(gate, make(static_cast<std::int64_t>(std::hash<std::string>{}(verb) >> 2), verb));
    EXPECT_EQ(r.kind, GateResult::Kind::execute) << verb << ": " << r.reason;
    EXPECT_EQ(verb_name(r.verb), verb);
  }
  EXPECT_EQ(gate.counts().passed, 6u);
}

TEST(CommandGate, RejectsUnknownVerbsAndOtherPayloadsWithAReason) {
  CommandGate gate("rig1");
  auto r = inspect(gate, make(1, "SELF_DESTRUCT"));
  EXPECT_EQ(r.kind, GateResult::Kind::reject);
  EXPECT_NE(r.reason.find("unknown verb 'SELF_DESTRUCT'"), std::string::npos) << r.reason;
  r = inspect(gate, make(2, "START", "rig2"));
  EXPECT_EQ(r.kind, GateResult::Kind::reject);
  EXPECT_NE(r.reason.find("'rig2'"), std::string::npos) << r.reason;
  EXPECT_EQ(gate.counts().rejected, 2u);
  EXPECT_EQ(gate.counts().other_payload, 1u);
  // A payload without keys does not authenticate: a tag is not checked.
  auto with_auth = make(3, "START");
  with_auth.auth = {1, 2, 3};
  with_auth.auth_size = 3;
  EXPECT_EQ(inspect(gate, with_auth).kind, GateResult::Kind::execute);
}

TEST(CommandGate, MalformedBytesAreCountedNotAnswered) {
  CommandGate gate("rig1");
  const std::vector<std::uint8_t> junk{1, 2, 3, 4, 5};
  EXPECT_EQ(gate.inspect(junk.data(), junk.size(), kNow).kind, GateResult::Kind::malformed);
  auto bytes = encoded(make(9, "START"));
  bytes.pop_back();  // truncated
  EXPECT_EQ(gate.inspect(bytes.data(), bytes.size(), kNow).kind, GateResult::Kind::malformed);
  bytes = encoded(make(9, "START"));
  bytes.push_back(0);  // trailing garbage
  EXPECT_EQ(gate.inspect(bytes.data(), bytes.size(), kNow).kind, GateResult::Kind::malformed);
  EXPECT_EQ(inspect(gate, make(0, "START")).kind, GateResult::Kind::malformed);  // id 0 is reserved
  EXPECT_EQ(gate.counts().malformed, 4u);
}

TEST(CommandGate, ReplayedIdsGetTheSameAnswerWithinTheWindow) {
  CommandGate gate("rig1", 2);
  command_ack_t ack;
  ack.request_id = 7;
  ack.accepted = true;
  ack.reason = "mapping started";
  ASSERT_EQ(inspect(gate, make(7, "START")).kind, GateResult::Kind::execute);
  gate.remember(ack);
  const auto replay = inspect(gate, make(7, "START"));
  EXPECT_EQ(replay.kind, GateResult::Kind::replay);
  EXPECT_EQ(replay.previous.reason, "mapping started");
  // Two newer ids push 7 out of a window of two.
  for (std::int64_t id : {8, 9}) {
    ack.request_id = id;
    gate.remember(ack);
  }
  EXPECT_EQ(inspect(gate, make(7, "START")).kind, GateResult::Kind::execute);
  EXPECT_EQ(inspect(gate, make(9, "START")).kind, GateResult::Kind::replay);
}

TEST(SessionState, FollowsIdleMappingStoppingIdle) {
  SessionMachine m;
  EXPECT_EQ(m.state(), SessionState::idle);
  EXPECT_TRUE(m.apply(SessionEvent::start).accepted);
  EXPECT_EQ(m.state(), SessionState::mapping);
  EXPECT_TRUE(m.apply(SessionEvent::stop).accepted);
  EXPECT_EQ(m.state(), SessionState::stopping);
  EXPECT_TRUE(m.apply(SessionEvent::stopped).accepted);
  EXPECT_EQ(m.state(), SessionState::idle);
}

TEST(SessionState, RejectsInvalidTransitionsWithAReasonAndKeepsTheState) {
  const struct {
    SessionState from;
    SessionEvent event;
    const char* reason;
  } cases[] = {
      {SessionState::idle, SessionEvent::stop, "not mapping"},
      {SessionState::idle, SessionEvent::stopped, "no stop in progress"},
      {SessionState::mapping, SessionEvent::start, "already mapping"},
      {SessionState::mapping, SessionEvent::stopped, "no stop in progress"},
      {SessionState::stopping, SessionEvent::start, "still stopping the last session"},
      {SessionState::stopping, SessionEvent::stop, "already stopping"},
  };
  for (const auto& c : cases) {
    const Transition t = next_state(c.from, c.event);
    EXPECT_FALSE(t.accepted);
    EXPECT_EQ(t.to, c.from);
    EXPECT_EQ(t.reason, c.reason);
  }
}

// HINT's key=value arguments: parsed back from what a client sends, and each
// bad one named.
TEST(LocaliseHint, ArgumentsRoundTripAndBadOnesAreNamed) {
  LocaliseHint hint;
  hint.x_m = 12.25;
  hint.y_m = -3.5;
  hint.radius_m = 4.0;
  hint.heading_deg = 271.5;
  hint.heading_tolerance_deg = 15.0;
  std::string error;
  const std::optional<LocaliseHint> back = parse_localise_hint(localise_hint_args(hint), error);
  ASSERT_TRUE(back.has_value()) << error;
  EXPECT_EQ(back->x_m, 12.25);
  EXPECT_EQ(back->y_m, -3.5);
  EXPECT_EQ(back->radius_m, 4.0);
  EXPECT_EQ(back->heading_deg, 271.5);
  EXPECT_EQ(back->heading_tolerance_deg, 15.0);
  const std::optional<LocaliseHint> plain = parse_localise_hint({"x=1", "y=2"}, error);
  ASSERT_TRUE(plain.has_value());
  EXPECT_FALSE(plain->heading_deg.has_value());  // any heading
  EXPECT_EQ(plain->radius_m, 5.0);
  const std::pair<std::vector<std::string>, const char*> bad[] = {
      {{"x=1"}, "x and y are needed"},
      {{"x=1", "y"}, "'y' is not key=value"},
      {{"x=1", "y=2m"}, "y: '2m' is not a number"},
      {{"x=1", "y=inf"}, "y: 'inf' is not a number"},
      {{"x=1", "y=2", "radius=0.1"}, "radius: 0.1 is outside 0.5..100"},
      {{"x=1", "y=2", "heading_tolerance=0"}, "heading_tolerance: 0 is outside 1..180"},
      {{"x=1", "y=2", "z=3"}, "unknown argument 'z'"},
  };
  for (const auto& [args, why] : bad) {
    error.clear();
    EXPECT_FALSE(parse_localise_hint(args, error).has_value()) << why;
    EXPECT_NE(error.find(why), std::string::npos) << error;
  }
}

}  // namespace
}  // namespace adit::protocol
