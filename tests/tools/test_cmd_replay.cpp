// adit replay and adit bench pipeline run as a user would, on a short session
// that `adit sim` writes for this test: one pose per scan in the trajectory,
// the pace honoured, bad captures named with exit status 2, and a capture sent
// over UDP loopback arriving whole at the pipeline.

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "daemon_process.hpp"
#include "run_program.hpp"
#include "sanitizers.hpp"
#include "shared_data.hpp"

namespace {

namespace fs = std::filesystem;
using adit::test::CommandRun;
CommandRun adit(const std::string& arguments) { return adit::test::run_adit(arguments); }

// An 11 s simulated drift with a VLP-16 (about 100 scans), written once and
// shared by the test processes (renamed into place whole, so never half-read);
// each process writes its outputs in a folder of its own.
class Replay : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    session_ = adit::test::binary_dir() / "test-sessions" / "replay-drift-11s";
    if (!fs::exists(session_ / "session.yaml")) {
      const fs::path partial = session_.string() + ".partial-" + std::to_string(::getpid());
      const CommandRun sim = adit("sim --scene drift --platform robot --sensor VLP-16 --duration 11 --seed 7 --out " +
                                  partial.string());
      ASSERT_EQ(sim.status, 0) << sim.output;
      std::error_code already_there;
      fs::rename(partial, session_, already_there);
      fs::remove_all(partial);
    }
    dir_ = adit::test::binary_dir() / "test-sessions" / ("replay-out-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static std::string config() { return " --config " + (session_ / "session.yaml").string(); }
  static nlohmann::json json_of(const CommandRun& run) {
    const auto start = run.output.find('{');
    return start == std::string::npos ? nlohmann::json() : nlohmann::json::parse(run.output.substr(start), nullptr, false);
  }

  static fs::path session_;
  static fs::path dir_;
};
fs::path Replay::session_;
fs::path Replay::dir_;

std::vector<double> stamps_of(const fs::path& tum) {
  std::vector<double> stamps;
  std::ifstream in(tum);
  for (std::string line; std::getline(in, line);) stamps.push_back(std::stod(line));
  return stamps;
}

TEST_F(Replay, WritesOnePosePerScanAsFastAsItCan) {
  const fs::path out = dir_ / "replay" / "trajectory.tum";
  const CommandRun run = adit("replay" + config() + " --out " + out.string() + " --json");
  ASSERT_EQ(run.status, 0) << run.output;
  const nlohmann::json j = json_of(run);
  ASSERT_TRUE(j.is_object()) << run.output;
  const auto scans = j["scans"].get<std::uint64_t>();
  EXPECT_GE(scans, 95U) << run.output;  // 10 s at 10 Hz
  const auto skipped = j["skipped_start_scans"].get<std::uint64_t>();  // an incomplete first scan
  EXPECT_LE(skipped, 1U);
  EXPECT_EQ(j["poses"].get<std::uint64_t>() + skipped, scans);
  EXPECT_EQ(j["invalid_poses"].get<std::uint64_t>(), 0U);
  EXPECT_EQ(j["dropped_packets"].get<std::uint64_t>(), 0U);
  EXPECT_EQ(j["dropped_scans"].get<std::uint64_t>(), 0U);
  EXPECT_GT(j["speed"].get<double>(), 0.0);
  EXPECT_GT(j["odometry_ms"]["median"].get<double>(), 0.0);
  EXPECT_GE(j["odometry_ms"]["p99"].get<double>(), j["odometry_ms"]["median"].get<double>());
  EXPECT_GT(j["peak_resident_mb"].get<double>(), 0.0);
  EXPECT_TRUE(j.contains("resident_growth")) << run.output;

  const std::vector<double> stamps = stamps_of(out);
  ASSERT_EQ(stamps.size() + skipped, scans);
  for (std::size_t i = 1; i < stamps.size(); ++i) EXPECT_GT(stamps[i], stamps[i - 1]) << "line " << i + 1;
}

TEST_F(Replay, PrintsTheFiguresForPeople) {
  const CommandRun run = adit("replay" + config() + " --pcap " + (session_ / "lidar.pcap").string());
  ASSERT_EQ(run.status, 0) << run.output;
  for (const char* figure : {"scans ", "odometry per scan: median", "latency", "x real time", "peak resident"})
    EXPECT_NE(run.output.find(figure), std::string::npos) << figure << " in\n" << run.output;
}

TEST_F(Replay, HonoursTheRequestedPace) {
  const CommandRun run = adit("replay" + config() + " --speed 4 --json");
  ASSERT_EQ(run.status, 0) << run.output;
  const nlohmann::json j = json_of(run);
  const double span = j["sensor_span_s"].get<double>();
  EXPECT_GT(span, 9.0);
  EXPECT_GE(j["duration_s"].get<double>(), 0.95 * span / 4.0) << run.output;
  EXPECT_EQ(adit("replay" + config() + " --realtime --speed 2").status, 2);
}

TEST_F(Replay, ReplaysADirectoryOfScans) {
  const fs::path scans = dir_ / "scans";
  const CommandRun decode = adit("decode " + (session_ / "lidar.pcap").string() + " --calibration " +
                                 (session_ / "VLP16.yaml").string() + " --out " + scans.string());
  ASSERT_EQ(decode.status, 0) << decode.output;
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(scans)) files += entry.path().extension() == ".pcd";
  ASSERT_GE(files, 95U);
  const fs::path out = dir_ / "scan-dir.tum";
  const CommandRun run = adit("replay" + config() + " --scan-dir " + scans.string() + " --out " + out.string() + " --json");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_EQ(json_of(run)["poses"].get<std::size_t>(), files);
  EXPECT_EQ(stamps_of(out).size(), files);
  const CommandRun paced = adit("replay" + config() + " --scan-dir " + scans.string() + " --realtime");
  EXPECT_EQ(paced.status, 2) << paced.output;
  EXPECT_NE(paced.output.find("--realtime"), std::string::npos) << paced.output;
}

TEST_F(Replay, AMissingOrCorruptCaptureIsNamedWithStatus2) {
  const fs::path missing = dir_ / "no-such.pcap";
  const CommandRun run = adit("replay" + config() + " --pcap " + missing.string());
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find(missing.string()), std::string::npos) << run.output;

  const fs::path corrupt = dir_ / "corrupt.pcap";
  std::ofstream(corrupt) << "this is not a capture file, just text long enough to hold a pcap header";
  const CommandRun bad = adit("replay" + config() + " --pcap " + corrupt.string());
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_NE(bad.output.find(corrupt.string()), std::string::npos) << bad.output;
  EXPECT_EQ(bad.output.find("scans "), std::string::npos) << "no figures after an error";

  EXPECT_EQ(adit("replay --config " + (dir_ / "none.yaml").string()).status, 2);
  EXPECT_EQ(adit("replay" + config() + " --pcap a.pcap --scan-dir b").status, 2);
}

TEST_F(Replay, BenchPipelineReceivesTheWholeCaptureOverLoopback) {
  // 4x the sensor's rate; 1x in a sanitizer build, whose pipeline cannot keep
  // 4x on two cores (CI under ASan: 25 of 109 scans dropped, 0.34x reached, and
  // once a datagram lost on loopback with none overflowing the socket).
  const std::string speed = adit::test::kSanitized ? "1" : "4";
  const CommandRun run = adit("bench pipeline" + config() + " --speed " + speed + " --json");
  ASSERT_EQ(run.status, 0) << run.output;
  const nlohmann::json j = json_of(run);
  ASSERT_TRUE(j.is_object()) << run.output;
  const nlohmann::json& file = j["file"];
  const nlohmann::json& udp = j["udp"];
  EXPECT_GT(udp["sent"].get<std::uint64_t>(), 1000U);
  EXPECT_EQ(udp["lost"].get<std::uint64_t>(), 0U) << run.output;
  EXPECT_EQ(udp["datagrams"].get<std::uint64_t>(), udp["sent"].get<std::uint64_t>());
  // Live, the last scan is never cut (no packet of the next revolution follows
  // it), and a busy machine may drop scans odometry cannot keep up with: each
  // is counted, every other one becomes a pose.
  EXPECT_GE(udp["scans"].get<std::uint64_t>() + 1, file["scans"].get<std::uint64_t>()) << run.output;
  // An incomplete first scan is skipped (counted), not made a pose.
  const auto count = [](const nlohmann::json& run, const char* key) { return run[key].get<std::uint64_t>(); };
  EXPECT_EQ(count(udp, "poses") + count(udp, "dropped_scans") + count(udp, "skipped_start_scans"), count(udp, "scans"));
  EXPECT_EQ(count(file, "poses") + count(file, "skipped_start_scans"), count(file, "scans"));
  EXPECT_LE(count(file, "skipped_start_scans"), 1U);
  EXPECT_GT(udp["latency_ms"]["p99"].get<double>(), 0.0);
  EXPECT_GE(udp["latency_ms"]["max"].get<double>(), udp["latency_ms"]["p99"].get<double>());
  // Latency covers the scan's odometry: paired per scan, the rest is never negative.
  EXPECT_GE(file["latency_beyond_odometry_ms"]["median"].get<double>(), 0.0);
  EXPECT_GE(udp["latency_beyond_odometry_ms"]["median"].get<double>(), 0.0);
}

}  // namespace

namespace {

// A session aditd recorded (raw recording is on by default) is mapped again
// from its own recordings and configuration: the same map.
TEST_F(Replay, AStoredSessionIsMappedAgainFromItsRecordings) {
  const fs::path work = dir_ / "stored";
  const std::string yaml = adit::test::aditd_yaml_for(session_, work / "state",
                                                      {"", "", true, "threads:\n  lock_memory: false\n"});
  fs::create_directories(work);
  std::ofstream(work / "aditd.yaml") << yaml;
  {
    adit::test::Daemon once({(adit::test::binary_dir() / "bin/aditd").string(), "--config", (work / "aditd.yaml").string(),
                             "--once"},
                            work / "aditd.log");
    ASSERT_EQ(once.wait_exit(120), 0) << "aditd --once failed (" << (work / "aditd.log").string() << ")";
  }
  std::vector<fs::path> sessions;
  for (const auto& e : fs::directory_iterator(work / "state" / "sessions")) sessions.push_back(e.path());
  ASSERT_EQ(sessions.size(), 1U);
  const fs::path stored = sessions[0];
  ASSERT_TRUE(fs::exists(stored / "lidar.pcap"));  // recorded by default
  ASSERT_TRUE(fs::exists(stored / "can.log"));
  const nlohmann::json first = nlohmann::json::parse(std::ifstream(stored / "summary.json"));
  EXPECT_TRUE(first["lidar"]["recording_stopped"].is_null());
  EXPECT_EQ(first["lidar"]["recorded_datagrams"], first["lidar"]["datagrams"]);

  const CommandRun again = adit("replay --session " + stored.string() + " --out-dir " + (work / "again").string());
  ASSERT_EQ(again.status, 0) << again.output;
  std::vector<fs::path> replayed;
  for (const auto& e : fs::directory_iterator(work / "again" / "sessions")) replayed.push_back(e.path());
  ASSERT_EQ(replayed.size(), 1U);
  const nlohmann::json second = nlohmann::json::parse(std::ifstream(replayed[0] / "summary.json"));
  EXPECT_EQ(second["poses"]["total"], first["poses"]["total"]);
  EXPECT_EQ(second["map"]["points"], first["map"]["points"]);
  EXPECT_NE(again.output.find(first["map"]["points"].dump() + " map points"), std::string::npos) << again.output;

  const CommandRun not_a_session = adit("replay --session " + work.string());
  EXPECT_EQ(not_a_session.status, 2);
  EXPECT_NE(not_a_session.output.find("config.yaml"), std::string::npos) << not_a_session.output;
}

}  // namespace
