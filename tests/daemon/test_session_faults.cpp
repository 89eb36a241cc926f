// A disk that fills up during a session: the raw recording stops first
// (a refused write, or free space below session.record_min_free_mb), the
// status says so, the journal stops on a refused write too, and the mapping
// goes on: the session is complete up to the fault.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/config/load.hpp"
#include "adit/daemon/journal_writer.hpp"
#include "adit/daemon/pipeline.hpp"
#include "adit/drivers/pcap_replay.hpp"
#include "adit/daemon/sessions.hpp"
#include "daemon_process.hpp"
#include "run_program.hpp"
#include "pipeline_run.hpp"
#include "sim_sessions.hpp"
#include "shared_data.hpp"

namespace adit::daemon {
namespace {

using namespace std::chrono_literals;


config::Config session_config(const std::filesystem::path& work, const std::string& extra) {
  return test::replay_config(test::mine_drive_12s(), work, extra);
}

// Every write refused (/dev/full: ENOSPC): the recording and the journal stop,
// the odometry and the map are those of a run with a disk to spare.
TEST(SessionFaults, AFullDiskStopsTheRecordingAndTheJournalNotTheMapping) {
  const std::filesystem::path work = test::binary_dir() / fmt::format("faults-full-{}", ::getpid());
  std::filesystem::remove_all(work);
  const config::Config c = session_config(work, "");
  const auto run = [&](const std::filesystem::path& record, const std::filesystem::path& journal) {
    auto pipeline = std::make_unique<Pipeline>(c, PipelineOptions{});
    SessionFiles files;
    files.record_file = record;
    files.journal_file = journal;
    files.journal_header = "{}";
    pipeline->start(files);
    pipeline->join();
    return pipeline;
  };
  const auto spared = run(work / "lidar.pcap", work / "journal.adj");
  const auto full = run("/dev/full", "/dev/full");
  const PipelineStats& s = full->stats();
  EXPECT_EQ(static_cast<RecordingStop>(s.recording_stopped.load()), RecordingStop::write_failed);
  EXPECT_EQ(static_cast<RecordingStop>(spared->stats().recording_stopped.load()), RecordingStop::recording);
  ASSERT_NE(full->journal(), nullptr);
  EXPECT_NE(full->journal()->fault().find("No space left"), std::string::npos) << full->journal()->fault();
  EXPECT_EQ(spared->journal()->fault(), "");
  EXPECT_GT(s.poses.load(), 100U);
  EXPECT_EQ(s.poses.load(), spared->stats().poses.load());
  EXPECT_EQ(full->map().size(), spared->map().size());
  std::filesystem::remove_all(work);
}

// The recording in parts (session.record_part_mb): each part under the size,
// the parts read back as one capture hold every recorded datagram, and the
// session maps again from them as from the original.
TEST(SessionFaults, TheRecordingGoesOnInPartsThatReadBackAsOneCapture) {
  const std::filesystem::path work = test::binary_dir() / fmt::format("faults-parts-{}", ::getpid());
  std::filesystem::remove_all(work);
  config::Config c = session_config(work, "");
  c.session.record_part_mb = 2.0;
  Pipeline pipeline(c, PipelineOptions{});
  SessionFiles files;
  files.record_file = work / "lidar.pcap";
  pipeline.start(files);
  pipeline.join();
  const PipelineStats& s = pipeline.stats();
  EXPECT_EQ(static_cast<RecordingStop>(s.recording_stopped.load()), RecordingStop::recording);
  int parts = 0;
  std::uint64_t bytes = 0;
  for (; std::filesystem::exists(drivers::pcap_part(work / "lidar.pcap", parts)); ++parts) {
    const std::uint64_t size = std::filesystem::file_size(drivers::pcap_part(work / "lidar.pcap", parts));
    EXPECT_LE(size, 2'000'000U) << "part " << parts;
    bytes += size;
  }
  EXPECT_GE(parts, 5) << "a 12 s VLP-16 drive is ~11 MB";
  EXPECT_EQ(bytes, s.recorded_bytes.load());
  drivers::PacedPcapReader reader(work / "lidar.pcap", 0.0);
  drivers::UdpDatagram d;
  std::uint64_t datagrams = 0;
  std::int64_t previous = 0;
  bool in_order = true;
  while (reader.next(d)) {
    ++datagrams;
    in_order = in_order && d.capture_time_ns >= previous;
    previous = d.capture_time_ns;
  }
  EXPECT_EQ(datagrams, s.recorded_datagrams.load());
  EXPECT_EQ(reader.parts(), parts);
  EXPECT_TRUE(in_order);

  config::Config again = c;
  again.lidar.pcap = (work / "lidar.pcap").string();
  Pipeline replayed(again, PipelineOptions{});
  replayed.start();
  replayed.join();
  EXPECT_EQ(replayed.stats().poses.load(), s.poses.load());
  std::filesystem::remove_all(work);
}

// Free space below the reserve: the recording stops at the next status, the
// status says why, and the session is mapped to its end.
TEST(SessionFaults, LowDiskStopsTheRecordingAndTheStatusSaysSo) {
  const std::filesystem::path work = test::binary_dir() / fmt::format("faults-low-{}", ::getpid());
  std::filesystem::remove_all(work);
  nlohmann::json summary;
  {
    // A reserve no disk has: the first status finds the disk "low".
    Sessions sessions(session_config(work, "session:\n  record_min_free_mb: 1e8\n"), {});
    const std::string id = sessions.start();
    std::string fault;
    const auto deadline = std::chrono::steady_clock::now() + 120s;
    while (!sessions.poll() && std::chrono::steady_clock::now() < deadline) {
      const StatusSample status = sessions.status_sample();
      if (status.fault.find("raw recording stopped") != std::string::npos) fault = status.fault;
      std::this_thread::sleep_for(20ms);
    }
    sessions.stop_and_wait();
    EXPECT_NE(fault.find("free disk space fell below session.record_min_free_mb"), std::string::npos) << fault;
    summary = nlohmann::json::parse(std::ifstream(sessions.folder(id) / "summary.json"));
  }  // Sessions' products thread ends here: it writes into the session folder until then
  EXPECT_EQ(summary["lidar"]["recording_stopped"], "free disk space fell below session.record_min_free_mb");
  EXPECT_LT(summary["lidar"]["recorded_datagrams"].get<std::size_t>(), summary["lidar"]["datagrams"].get<std::size_t>());
  EXPECT_GT(summary["poses"]["total"].get<std::size_t>(), 100U);  // mapped to the end: 12 s at 10 Hz
  EXPECT_GT(summary["map"]["points"].get<std::size_t>(), 10'000U);
  std::filesystem::remove_all(work);
}

}  // namespace
}  // namespace adit::daemon
