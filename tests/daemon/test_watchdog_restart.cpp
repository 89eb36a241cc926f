// A worker that stalls (a driver stuck in the kernel, a deadlock): aditd's
// supervisor stops feeding systemd's watchdog, systemd restarts the service
// (WatchdogSec, WatchdogSignal=SIGABRT, Restart=on-failure: systemd/aditd.service),
// and the session the stalled aditd was mapping is recovered from its journal.
//
// The test plays systemd: it owns the notification socket (NOTIFY_SOCKET,
// WATCHDOG_USEC, as sd_notify(3) reads them), aborts aditd when WATCHDOG=1
// has not come for WatchdogSec, and starts it again. The stall is real: the
// mapping thread alone is stopped from outside with ptrace (PTRACE_INTERRUPT
// stops one thread; the others, the supervisor among them, run on).
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/ptrace.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "daemon_process.hpp"
#include "run_program.hpp"
#include "shared_data.hpp"
#include "sim_sessions.hpp"

namespace adit::test {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// systemd's end of sd_notify: a datagram socket bound to a path.
class NotifySocket {
 public:
  explicit NotifySocket(const std::filesystem::path& path) : path_(path) {
    std::filesystem::remove(path);
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::snprintf(a.sun_path, sizeof a.sun_path, "%s", path.c_str());
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) throw std::runtime_error("bind " + path.string());
    const timeval t{0, 50'000};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &t, sizeof t);
  }
  ~NotifySocket() {
    ::close(fd_);
    std::filesystem::remove(path_);
  }
  // The next message, or "" after 50 ms.
  std::string receive() {
    char buffer[4096];
    const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
    return n > 0 ? std::string(buffer, static_cast<std::size_t>(n)) : std::string();
  }

 private:
  std::filesystem::path path_;
  int fd_ = -1;
};

pid_t thread_named(pid_t pid, const std::string& name) {
  for (const auto& task : std::filesystem::directory_iterator(fmt::format("/proc/{}/task", pid))) {
    std::string comm;
    std::getline(std::ifstream(task.path() / "comm"), comm);
    if (comm == name) return static_cast<pid_t>(std::stol(task.path().filename().string()));
  }
  return -1;
}

// A process that stops thread `tid` and holds it stopped until killed.
pid_t stall(pid_t tid) {
  const pid_t tracer = ::fork();
  if (tracer == 0) {
    if (::ptrace(PTRACE_SEIZE, tid, nullptr, nullptr) != 0 || ::ptrace(PTRACE_INTERRUPT, tid, nullptr, nullptr) != 0)
      ::_exit(3);
    for (;;) ::pause();
  }
  return tracer;
}

TEST(WatchdogRestart, AStalledWorkerStopsTheWatchdogAndTheRestartRecoversItsSession) {
  const std::filesystem::path session = mine_drive_12s();
  const std::filesystem::path work = binary_dir() / fmt::format("watchdog-{}", ::getpid());
  std::filesystem::remove_all(work);
  std::filesystem::create_directories(work);
  const std::string payload = fmt::format("watchdog{}", ::getpid());
  const std::string url = fmt::format("udpm://239.255.76.67:{}?ttl=0", 20000 + (::getpid() + 23) % 30000);
  const std::filesystem::path config = work / "aditd.yaml";
  std::ofstream(config) << aditd_yaml_for(session, work / "state",
                                          {payload, url, false, "session:\n  exports: [ply]\nthreads:\n  lock_memory: false\n"});
  const std::string aditd_bin = (binary_dir() / "bin/aditd").string();
  const std::string client = fmt::format("--payload {} --lcm-url '{}' --timeout 5", payload, url);
  constexpr auto kWatchdog = 2s;  // WatchdogSec

  NotifySocket notify(work / "notify.sock");
  std::string id;
  double stalled_after_s = 0.0, aborted_after_s = 0.0;
  bool said_stalled = false;
  {
    Daemon aditd({aditd_bin, "--config", config.string()}, work / "aditd-stalled.log",
                 {"NOTIFY_SOCKET=" + (work / "notify.sock").string(),
                  fmt::format("WATCHDOG_USEC={}", std::chrono::microseconds(kWatchdog).count())});
    const Clock::time_point launched = Clock::now();
    bool ready = false;
    while (!ready && Clock::now() - launched < 10s) ready = notify.receive().starts_with("READY=1");
    ASSERT_TRUE(ready) << "no READY=1 (aditd-stalled.log)";
    const CommandRun start = run_adit("start " + client);
    ASSERT_EQ(start.status, 0) << start.output;
    id = start.output.substr(start.output.find("session ") + 8);
    id = id.substr(0, id.find_first_of(" \n:"));
    std::this_thread::sleep_for(3s);  // mapping, journalled

    const pid_t tid = thread_named(aditd.pid(), "adit-mapping");
    ASSERT_GT(tid, 0) << "no thread named mapping: " << [&] {
      std::string names;
      for (const auto& task : std::filesystem::directory_iterator(fmt::format("/proc/{}/task", aditd.pid()))) {
        std::string comm;
        std::getline(std::ifstream(task.path() / "comm"), comm);
        names += comm + " ";
      }
      return names;
    }();
    const Clock::time_point stalled = Clock::now();
    const pid_t tracer = stall(tid);
    std::this_thread::sleep_for(100ms);
    if (int traced = 0; ::waitpid(tracer, &traced, WNOHANG) == tracer)
      GTEST_SKIP() << "ptrace is not permitted here (CAP_SYS_PTRACE, kernel.yama.ptrace_scope): no way to stall one thread";
    Clock::time_point last_pet = stalled;
    while (Clock::now() - last_pet < kWatchdog && Clock::now() - stalled < 30s) {
      const std::string m = notify.receive();
      if (m.find("WATCHDOG=1") != std::string::npos) last_pet = Clock::now();
      if (m.find("STATUS=stalled: mapping") != std::string::npos) {
        said_stalled = true;
        stalled_after_s = std::chrono::duration<double>(Clock::now() - stalled).count();
      }
    }
    // systemd: WatchdogSignal=SIGABRT, then SIGKILL after TimeoutAbortSec.
    aborted_after_s = std::chrono::duration<double>(Clock::now() - stalled).count();
    ::kill(aditd.pid(), SIGABRT);
    // The stopped thread's exit is reported to its tracer: end the tracer so
    // that the process can be reaped.
    ::kill(tracer, SIGKILL);
    ::waitpid(tracer, nullptr, 0);
    const int status = aditd.wait_exit(10);
    EXPECT_NE(status, 0) << "an aborted aditd is a failure systemd restarts";
  }
  EXPECT_TRUE(said_stalled) << "STATUS=stalled: mapping was never sent";
  EXPECT_LT(aborted_after_s, 6.0) << "the watchdog fires within the stall threshold plus WatchdogSec";

  // Restart=on-failure: the next aditd rebuilds the interrupted session.
  Daemon restarted({aditd_bin, "--config", config.string()}, work / "aditd-restarted.log");
  ASSERT_EQ(run_adit("ping " + client).status, 0);
  const std::filesystem::path dir = work / "state" / "sessions" / id;
  for (int i = 0; i < 300 && !std::filesystem::exists(dir / "summary.json"); ++i) std::this_thread::sleep_for(100ms);
  ASSERT_TRUE(std::filesystem::exists(dir / "summary.json")) << dir;
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(dir / "summary.json"));
  ASSERT_TRUE(summary.contains("recovered")) << summary.dump();
  EXPECT_GT(summary["map"]["points"].get<std::size_t>(), 10000U) << "the 3 s mapped before the stall";
  const CommandRun listed = run_adit("sessions " + client);
  EXPECT_NE(listed.output.find(id + " recovered"), std::string::npos) << listed.output;
  std::printf("stall: said after %.1f s, aborted after %.1f s (WatchdogSec 2 s); recovered %zu points\n",
              stalled_after_s, aborted_after_s, summary["map"]["points"].get<std::size_t>());
  restarted.stop();
  std::filesystem::remove_all(work);
}

}  // namespace
}  // namespace adit::test
