// Command authentication: canonical bytes, HMAC tags, key files, and the
// gate's checks with keys (unsigned, bad tag, other payload, stale, replayed).
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sodium.h>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/protocol/command_auth.hpp"
#include "adit/protocol/command_gate.hpp"
#include "shared_data.hpp"

namespace adit::protocol {
namespace {

constexpr std::int64_t kNow = 1'795'000'000'000'000;  // the payload's clock in these tests (µs)
constexpr std::int64_t kWindow = 30'000'000;

CommandKey key_of(std::uint8_t fill) {
  std::array<std::uint8_t, kCommandKeyBytes> secret{};
  secret.fill(fill);
  return CommandKey(std::span<const std::uint8_t, kCommandKeyBytes>(secret));
}

command_t make(std::int64_t id, std::string verb, std::string payload = "rig1", std::int64_t utime = kNow) {
  command_t c;
  c.utime = utime;
  c.schema = 1;
  c.request_id = id;
  c.payload_id = std::move(payload);
  c.verb = std::move(verb);
  c.n_args = 0;
  c.auth_size = 0;
  return c;
}

command_t signed_with(command_t c, const CommandKey& key) {
  sign_command(c, key);
  return c;
}

std::vector<std::uint8_t> encoded(const command_t& c) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(c.getEncodedSize()));
  c.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

GateResult inspect(CommandGate& gate, const command_t& c, std::int64_t now = kNow) {
  const auto bytes = encoded(c);
  return gate.inspect(bytes.data(), bytes.size(), now);
}

CommandGate keyed_gate(std::size_t window = 1024) {
  CommandGate gate("rig1", window);
  gate.set_keys({key_of(7)}, kWindow);
  return gate;
}

TEST(CommandAuth, CanonicalBytesFollowTheDocumentedLayout) {
  command_t c = make(0x0102030405060708, "PING", "ab", 0x1112131415161718);
  c.args = {"x=1"};
  c.n_args = 1;
  const KeyId id{9, 9, 9, 9, 9, 9, 9, 9};
  const std::vector<std::uint8_t> bytes = canonical_command_bytes(c, id);
  std::vector<std::uint8_t> expected;
  for (char ch : std::string("adit-command-v1")) expected.push_back(static_cast<std::uint8_t>(ch));
  expected.insert(expected.end(), id.begin(), id.end());
  expected.push_back(1);
  for (std::uint8_t b : {0x11, 0x12, 0x13, 0x14, 0x15, 0x16, 0x17, 0x18}) expected.push_back(b);  // utime
  expected.insert(expected.end(), {0, 1});                                                       // schema
  for (std::uint8_t b : {1, 2, 3, 4, 5, 6, 7, 8}) expected.push_back(b);                          // request id
  expected.insert(expected.end(), {0, 0, 0, 2, 'a', 'b'});
  expected.insert(expected.end(), {0, 0, 0, 4, 'P', 'I', 'N', 'G'});
  expected.insert(expected.end(), {0, 0, 0, 1});
  expected.insert(expected.end(), {0, 0, 0, 3, 'x', '=', '1'});
  EXPECT_EQ(bytes, expected);
}

TEST(CommandAuth, TagIsHmacSha256OfTheCanonicalBytes) {
  const CommandKey key = key_of(7);
  const command_t c = signed_with(make(42, "START"), key);
  ASSERT_EQ(c.auth.size(), kAuthBytes);
  EXPECT_EQ(c.auth_size, static_cast<std::int32_t>(kAuthBytes));
  EXPECT_EQ(c.auth[0], kAuthSchemeHmacSha256);
  // Independent computation: libsodium's one-shot HMAC over the documented bytes.
  const auto bytes = canonical_command_bytes(c, key.id());
  std::array<std::uint8_t, 32> tag{};
  crypto_auth_hmacsha256(tag.data(), bytes.data(), bytes.size(), key.secret().data());
  EXPECT_TRUE(std::equal(tag.begin(), tag.end(), c.auth.begin() + 9));
  const std::array<CommandKey, 1> keys{key};
  EXPECT_EQ(verify_command(c, keys).verdict, AuthVerdict::ok);
}

TEST(CommandAuth, EveryFieldIsCovered) {
  const CommandKey key = key_of(7);
  const std::array<CommandKey, 1> keys{key};
  command_t base = make(42, "EXPORT");
  base.args = {"session-1"};
  base.n_args = 1;
  base = signed_with(base, key);
  const std::vector<std::function<void(command_t&)>> changes{
      [](command_t& c) { c.utime += 1; },          [](command_t& c) { c.schema = 2; },
      [](command_t& c) { c.request_id += 1; },     [](command_t& c) { c.payload_id = "rig2"; },
      [](command_t& c) { c.verb = "STOP"; },       [](command_t& c) { c.args[0] = "session-2"; },
      [](command_t& c) { c.args.push_back("x"); c.n_args = 2; },
      [](command_t& c) { c.auth[20] ^= 1; },       [](command_t& c) { c.auth[1] ^= 1; }};
  for (std::size_t i = 0; i < changes.size(); ++i) {
    command_t c = base;
    changes[i](c);
    EXPECT_NE(verify_command(c, keys).verdict, AuthVerdict::ok) << "change " << i;
  }
  EXPECT_EQ(verify_command(base, keys).verdict, AuthVerdict::ok);
}

TEST(CommandAuth, GateRejectsUnsignedBadTagOtherPayloadStaleAndReplayed) {
  CommandGate gate = keyed_gate();
  const CommandKey key = key_of(7);
  auto r = inspect(gate, make(1, "START"));
  EXPECT_EQ(r.kind, GateResult::Kind::reject);
  EXPECT_EQ(r.reason.rfind("unsigned:", 0), 0u) << r.reason;
  EXPECT_FALSE(r.remember);
  r = inspect(gate, signed_with(make(2, "START"), key_of(8)));
  EXPECT_EQ(r.reason.rfind("bad tag:", 0), 0u) << r.reason;
  EXPECT_NE(r.reason.find(key_id_hex(key_of(8).id())), std::string::npos) << r.reason;
  command_t tampered = signed_with(make(3, "PING"), key);
  tampered.verb = "STOP";
  r = inspect(gate, tampered);
  EXPECT_EQ(r.reason, "bad tag: the tag does not match the command's content");
  EXPECT_FALSE(r.remember);
  r = inspect(gate, signed_with(make(4, "START", "rig2"), key));
  EXPECT_EQ(r.reason.rfind("other payload:", 0), 0u) << r.reason;
  r = inspect(gate, signed_with(make(5, "START", "rig1", kNow - kWindow - 1), key));
  EXPECT_EQ(r.reason.rfind("stale:", 0), 0u) << r.reason;
  r = inspect(gate, signed_with(make(6, "START", "rig1", kNow + kWindow + 1), key));
  EXPECT_EQ(r.reason.rfind("stale:", 0), 0u) << r.reason;
  // Inside the window, both ways: executed.
  EXPECT_EQ(inspect(gate, signed_with(make(7, "PING", "rig1", kNow - kWindow), key)).kind, GateResult::Kind::execute);
  EXPECT_EQ(inspect(gate, signed_with(make(8, "PING", "rig1", kNow + kWindow), key)).kind, GateResult::Kind::execute);
  const GateCounts& n = gate.counts();
  EXPECT_EQ(n.unsigned_commands, 1u);
  EXPECT_EQ(n.bad_tag, 2u);
  EXPECT_EQ(n.other_payload, 1u);
  EXPECT_EQ(n.stale, 2u);
  EXPECT_EQ(n.rejected, 6u);
  EXPECT_EQ(n.passed, 2u);
}

TEST(CommandAuth, ReplaysGetTheStoredAnswerThenAreRejectedOnceForgotten) {
  CommandGate gate = keyed_gate(2);
  const CommandKey key = key_of(7);
  const command_t start = signed_with(make(10, "START"), key);
  ASSERT_EQ(inspect(gate, start).kind, GateResult::Kind::execute);
  command_ack_t ack;
  ack.request_id = 10;
  ack.accepted = true;
  ack.reason = "mapping started";
  gate.remember(ack);
  const auto again = inspect(gate, start);  // a client's retry, or a replay: answered, not executed
  EXPECT_EQ(again.kind, GateResult::Kind::replay);
  EXPECT_EQ(again.previous.reason, "mapping started");
  // Unsigned junk cannot push the answer out of the memory...
  for (std::int64_t id = 100; id < 110; ++id) {
    const auto r = inspect(gate, make(id, "PING"));
    if (r.remember) gate.remember(ack);
  }
  EXPECT_EQ(inspect(gate, start).kind, GateResult::Kind::replay);
  // ...but newer signed commands do; the replay is then refused, not run again.
  for (std::int64_t id : {11, 12}) {
    ASSERT_EQ(inspect(gate, signed_with(make(id, "PING"), key)).kind, GateResult::Kind::execute);
    ack.request_id = id;
    gate.remember(ack);
  }
  const auto late = inspect(gate, start, kNow + 1'000'000);
  EXPECT_EQ(late.kind, GateResult::Kind::reject);
  EXPECT_EQ(late.reason.rfind("replayed:", 0), 0u) << late.reason;
  EXPECT_EQ(gate.counts().replay_rejected, 1u);
  // Once the window has passed, the same bytes are stale.
  EXPECT_EQ(inspect(gate, start, kNow + kWindow + 1).reason.rfind("stale:", 0), 0u);
}

TEST(CommandAuth, RotationAcceptsEveryListedKey) {
  CommandGate gate("rig1");
  gate.set_keys({key_of(1), key_of(2)}, kWindow);
  EXPECT_EQ(inspect(gate, signed_with(make(1, "PING"), key_of(1))).kind, GateResult::Kind::execute);
  EXPECT_EQ(inspect(gate, signed_with(make(2, "PING"), key_of(2))).kind, GateResult::Kind::execute);
  gate.set_keys({key_of(2)}, kWindow);
  EXPECT_EQ(inspect(gate, signed_with(make(3, "PING"), key_of(1))).reason.rfind("bad tag:", 0), 0u);
  gate.set_keys({}, kWindow);  // no keys: not authenticated
  EXPECT_EQ(inspect(gate, make(4, "PING")).kind, GateResult::Kind::execute);
}

// The fuzz target's signed seeds must stay valid, or it fuzzes only the tag
// check: each verifies with the key of 32 bytes 0x07 at the target's clock.
TEST(CommandAuth, FuzzSeedsAreSignedCommandsTheKeyedGateExecutes) {
  CommandGate gate = keyed_gate();
  for (int i = 0; i < 3; ++i) {
    const auto path = ::adit::test::source_dir() / fmt::format("tests/fuzz/seeds/protocol/signed_{}.bin", i);
    std::ifstream in(path, std::ios::binary);
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_FALSE(bytes.empty()) << path;
    const auto r = gate.inspect(bytes.data(), bytes.size(), kNow);
    EXPECT_EQ(r.kind, GateResult::Kind::execute) << path << ": " << r.reason;
  }
}

class KeyFile : public ::testing::Test {
 protected:
  std::filesystem::path dir = std::filesystem::temp_directory_path() / ("adit-keys-" + std::to_string(::getpid()));
  void SetUp() override { std::filesystem::create_directories(dir); }
  void TearDown() override { std::filesystem::remove_all(dir); }
};

TEST_F(KeyFile, WrittenWithMode0600AndReadBack) {
  const CommandKey key = CommandKey::generate();
  const auto path = dir / "k";
  ::umask(0);  // even then the file is 0600
  write_key_file(path, key, false);
  ::umask(022);
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0600u);
  const auto keys = read_key_file(path);
  ASSERT_EQ(keys.size(), 1u);
  EXPECT_EQ(keys[0].id(), key.id());
  EXPECT_THROW(write_key_file(path, key, false), InputError);  // no silent overwrite
  const CommandKey next = CommandKey::generate();
  write_key_file(path, next, true);
  EXPECT_EQ(read_key_file(path)[0].id(), next.id());
  EXPECT_NE(key.id(), next.id());
}

TEST_F(KeyFile, RefusesGroupOrWorldAccessNamingTheFile) {
  const auto path = dir / "open.key";
  write_key_file(path, CommandKey::generate(), false);
  for (mode_t mode : {0640, 0604, 0660, 0644, 0610}) {
    ::chmod(path.c_str(), mode);
    try {
      read_key_file(path);
      ADD_FAILURE() << "mode " << std::oct << mode << " accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.where(), path.string());
      EXPECT_NE(e.reason().find("chmod 600"), std::string::npos) << e.reason();
    }
  }
  ::chmod(path.c_str(), 0400);
  EXPECT_EQ(read_key_file(path).size(), 1u);
  EXPECT_THROW(read_key_file(dir / "missing.key"), InputError);
  EXPECT_THROW(read_key_file(dir), InputError);  // a directory
}

TEST(KeyFileText, BadLinesNameFileAndLine) {
  const std::string good = std::string(kKeyFileWord) + " " + std::string(64, 'a');
  EXPECT_EQ(parse_key_file("# comment\n\n" + good + "\n" + std::string(kKeyFileWord) + " " + std::string(64, 'B'), "k").size(),
            2u);
  const auto reason = [](const std::string& text) {
    try {
      parse_key_file(text, "k.key");
    } catch (const InputError& e) {
      return e.where() + ": " + e.reason();
    }
    return std::string("accepted");
  };
  EXPECT_EQ(reason(""), "k.key: no key in the file (expected a line 'adit-command-key-v1 <hex>')");
  EXPECT_EQ(reason("# only\n"), "k.key: no key in the file (expected a line 'adit-command-key-v1 <hex>')");
  EXPECT_EQ(reason("#\nssh-rsa AAAA\n").rfind("k.key:2: expected", 0), 0u);
  EXPECT_EQ(reason(std::string(kKeyFileWord) + " " + std::string(63, 'a')).rfind("k.key:1: the key must be 64 hex", 0), 0u);
  EXPECT_EQ(reason(std::string(kKeyFileWord) + " " + std::string(62, 'a') + "zz").rfind("k.key:1: the key must", 0), 0u);
  EXPECT_EQ(reason(std::string(kKeyFileWord)).rfind("k.key:1: the key must", 0), 0u);
}

}  // namespace
}  // namespace adit::protocol
