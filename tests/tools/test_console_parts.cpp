// adit console's parts without a network: the event hub's resume and
// resynchronisation (a browser that reconnects), its wake-up across threads,
// the operator passphrase (hash, check, file errors, tokens), and which of a
// session's files a browser may fetch.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <thread>

#include "adit/common/error.hpp"
#include "console_events.hpp"
#include "console_passphrase.hpp"
#include "console_sessions.hpp"
#include "temp_file.hpp"

namespace adit::tools::console {
namespace {

using namespace std::chrono_literals;

TEST(ConsoleEvents, AReconnectingStreamResumesAfterItsLastIdOrIsToldToResynchronise) {
  EventHub hub(4);
  for (int i = 0; i < 3; ++i) hub.publish("pose", std::to_string(i));
  const auto all = hub.wait_after(0, 0ms);
  ASSERT_EQ(all.events.size(), 3u);
  EXPECT_FALSE(all.lost);
  const auto rest = hub.wait_after(all.events[0].id, 0ms);  // reconnected after the first
  ASSERT_EQ(rest.events.size(), 2u);
  EXPECT_EQ(rest.events[0].data, "1");
  EXPECT_FALSE(rest.lost);
  for (int i = 3; i < 8; ++i) hub.publish("pose", std::to_string(i));  // only the last 4 kept
  const auto behind = hub.wait_after(all.events[0].id, 0ms);
  EXPECT_TRUE(behind.lost);
  EXPECT_EQ(hub.wait_after(hub.last_id(), 10ms).events.size(), 0u);  // nothing new: waits, then empty
  EXPECT_EQ(sse_frame({7, "status", "{\"a\":1}"}, "c0ffee"), "id: c0ffee.7\nevent: status\ndata: {\"a\":1}\n\n");
  EXPECT_EQ(resume_after("c0ffee.7", "c0ffee"), 7u);
  EXPECT_EQ(resume_after("beef.7", "c0ffee"), std::nullopt);  // another console's (restarted): start afresh
  EXPECT_EQ(resume_after("c0ffee.7x", "c0ffee"), std::nullopt);
  EXPECT_EQ(resume_after("", "c0ffee"), std::nullopt);
}

TEST(ConsoleEvents, AWaitingStreamWakesForAnEventAndForClosing) {
  EventHub hub;
  const std::uint64_t last = hub.last_id();
  std::thread producer([&] {
    std::this_thread::sleep_for(20ms);
    hub.publish("tiles", "x");
  });
  const auto t0 = std::chrono::steady_clock::now();
  const auto got = hub.wait_after(last, 5s);
  producer.join();
  ASSERT_EQ(got.events.size(), 1u);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 2s);
  std::thread closer([&] {
    std::this_thread::sleep_for(20ms);
    hub.close();
  });
  EXPECT_TRUE(hub.wait_after(hub.last_id(), 5s).events.empty());
  closer.join();
  EXPECT_TRUE(hub.closed());
}

TEST(ConsolePassphrase, OnlyTheRightPassphraseUnlocksAndTokensAreChecked) {
  const PassphraseHash h = hash_passphrase("open sesame", 1000);
  EXPECT_TRUE(passphrase_matches(h, "open sesame"));
  EXPECT_FALSE(passphrase_matches(h, "open sesame "));
  EXPECT_FALSE(passphrase_matches(h, ""));
  EXPECT_NE(format_hash(h), format_hash(hash_passphrase("open sesame", 1000)));  // salted

  const test::TempFile file("");
  std::ofstream(file.path()) << format_hash(h) << "\n";
  ControlGate gate(read_hash_file(file.path()));
  EXPECT_TRUE(gate.locked());
  EXPECT_FALSE(gate.unlock("guess").has_value());
  EXPECT_FALSE(gate.allows(""));
  EXPECT_FALSE(gate.allows("0123"));
  const auto token = gate.unlock("open sesame");
  ASSERT_TRUE(token.has_value());
  EXPECT_EQ(token->size(), 48u);
  EXPECT_TRUE(gate.allows(*token));

  ControlGate open(std::nullopt);  // no passphrase set: control is open
  EXPECT_FALSE(open.locked());
  EXPECT_TRUE(open.allows(""));
}

TEST(ConsolePassphrase, ABadHashFileNamesTheFileAndWhatIsWrong) {
  const test::TempFile file("");
  const auto problem = [&](const std::string& content) {
    std::ofstream(file.path()) << content;
    try {
      read_hash_file(file.path());
    } catch (const InputError& e) {
      EXPECT_EQ(e.where(), file.path().string() + ":1");
      return e.reason();
    }
    return std::string("accepted");
  };
  EXPECT_NE(problem("hunter2\n").find("not a 'pbkdf2-sha256$"), std::string::npos);
  EXPECT_NE(problem("pbkdf2-sha256$x$00112233445566778899$00\n").find("iterations 'x'"), std::string::npos);
  EXPECT_NE(problem("pbkdf2-sha256$10$0011223344556677$00\n").find("outside"), std::string::npos);
  EXPECT_NE(problem("pbkdf2-sha256$1000$zz$00\n").find("salt"), std::string::npos);
  EXPECT_NE(problem("pbkdf2-sha256$1000$0011223344556677$abcd\n").find("32 bytes"), std::string::npos);
}

// A browser names a file; only these reach a path, each where the payload
// writes it; the session list says which pictures are made.
TEST(ConsoleSessions, OnlyTheSessionsOwnFilesAndPicturesAreServedFromWhereThePayloadWritesThem) {
  EXPECT_EQ(session_file("trajectory.tum")->path, "trajectory.tum");
  EXPECT_EQ(session_file("summary.json")->type, "application/json");
  EXPECT_EQ(session_file("top_view.png")->path, "products/top_view.png");
  EXPECT_EQ(session_file("top_view.png")->type, "image/png");
  EXPECT_EQ(session_file("sections.csv")->path, "products/sections/sections.csv");
  EXPECT_EQ(session_file("section_007.svg")->path, "products/sections/section_007.svg");
  EXPECT_EQ(session_file("section_007.svg")->type, "image/svg+xml");
  for (const char* refused : {"config.yaml", "lidar.pcap", "section_.svg", "section_0a1.svg", "section_1234567.svg",
                              "section_001.png", "occupancy.bt", "../summary.json", ""})
    EXPECT_FALSE(session_file(refused).has_value()) << refused;

  const test::TempFolder root;
  const ScanNames names(root.path() / "names.json");
  std::filesystem::create_directories(root.path() / "s1");
  std::filesystem::create_directories(root.path() / "s2" / "products" / "sections");
  for (const char* f : {"products/top_view.png", "products/sections/section_000.svg",
                        "products/sections/section_001.svg", "products/sections/sections.csv"})
    std::ofstream(root.path() / "s2" / f) << "x";
  const nlohmann::json listed = describe_sessions({"s1", "s2 recovered"}, names, root.path());
  ASSERT_EQ(listed.size(), 2U);
  EXPECT_EQ(listed[0]["top_view"], false) << "no products yet";
  EXPECT_EQ(listed[0]["sections"], 0);
  EXPECT_EQ(listed[1]["id"], "s2");
  EXPECT_EQ(listed[1]["top_view"], true);
  EXPECT_EQ(listed[1]["sections"], 2) << "the drawings, not the table";
}

}  // namespace
}  // namespace adit::tools::console
