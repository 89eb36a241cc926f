#pragma once
// aditd (or any program) as a child process with its output in a log file:
// stopped as systemd stops it (SIGTERM) or killed as a crash or a pulled
// battery kills it (SIGKILL). And the aditd configuration that replays a
// simulated session (`adit sim`'s session.yaml) in a test's own folder.

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace adit::test {

class Daemon {
 public:
  // `environment`: NAME=value entries added to the child's (e.g. LD_PRELOAD).
  Daemon(const std::vector<std::string>& argv, const std::filesystem::path& log,
         const std::vector<std::string>& environment = {}) {
    pid_ = ::fork();
    if (pid_ == 0) {
      const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fd, STDOUT_FILENO);
      ::dup2(fd, STDERR_FILENO);
      for (const std::string& e : environment) ::putenv(const_cast<char*>(e.c_str()));
      std::vector<char*> args;
      for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      ::execv(args[0], args.data());
      ::_exit(127);
    }
  }
  ~Daemon() {
    if (pid_ > 0) stop();
  }
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;

  // SIGTERM, then the exit status (-1 if it did not exit within 30 s).
  int stop() {
    ::kill(pid_, SIGTERM);
    return wait_exit(30);
  }
  // Waits for it to exit by itself (aditd --once): its exit status, or -1
  // (and killed) when it has not within `seconds`.
  int wait_exit(int seconds) {
    using namespace std::chrono_literals;
    int status = 0;
    for (int i = 0; i < 10 * seconds; ++i) {
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(100ms);
    }
    kill_now();
    return -1;
  }
  pid_t pid() const { return pid_; }
  // SIGKILL: no handler runs, nothing is flushed.
  void kill_now() {
    ::kill(pid_, SIGKILL);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
  }

 private:
  pid_t pid_ = -1;
};

// What a test changes in a simulated session's session.yaml.
struct SimConfigEdits {
  std::string payload;       // payload.id; "" keeps the simulator's
  std::string lcm_url;       // "" keeps the default URL
  bool as_fast_as_possible = false;  // lidar.replay_speed 0 (a replay waits: nothing dropped)
  std::string extra_yaml;    // appended (sections the session.yaml lacks)
};

// The simulator's own session.yaml (LiDAR, CAN, extrinsics) with absolute
// paths into `session`, the state folder `state_dir` and `edits`.
inline std::string aditd_yaml_for(const std::filesystem::path& session, const std::filesystem::path& state_dir,
                                  const SimConfigEdits& edits) {
  std::ifstream in(session / "session.yaml");
  std::string yaml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto replace_line = [&yaml](const std::string& start, const std::string& to) {
    const std::size_t at = yaml.find(start);
    if (at == std::string::npos) return;
    const std::size_t end = yaml.find('\n', at + 1);
    yaml.replace(at, (end == std::string::npos ? yaml.size() : end) - at, to);
  };
  if (!edits.payload.empty()) replace_line("\n  id: ", "\n  id: " + edits.payload);
  replace_line("\n  state_dir: ", "\n  state_dir: " + state_dir.string());
  // The session's files (the capture, the LiDAR's calibration or metadata, the CAN log) by absolute path.
  const auto in_session = [&](const std::string& start) {
    const std::size_t at = yaml.find(start);
    if (at == std::string::npos) return;
    const std::size_t from = at + start.size();
    const std::size_t end = yaml.find('\n', from);
    const std::string name = yaml.substr(from, (end == std::string::npos ? yaml.size() : end) - from);
    replace_line(start, start + (session / name).string());
  };
  in_session("\n  pcap: ");
  in_session("\n  calibration: ");
  in_session("\n  log: ");
  if (!edits.lcm_url.empty()) replace_line("\n  url: ", "\n  url: " + edits.lcm_url);
  if (edits.as_fast_as_possible) replace_line("\n  replay_speed: ", "\n  replay_speed: 0");
  return yaml + edits.extra_yaml;
}

}  // namespace adit::test
