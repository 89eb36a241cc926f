// adit console: serves the tablet's web app from the payload (or a laptop):
// a live 3D view, health, start/stop and session downloads for any browser on
// the network, while being itself an LCM client of aditd like the tablet.
// docs/CONSOLE.md.

#include <signal.h>

#include <atomic>
#include <iostream>
#include <memory>
#include <thread>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/config/load.hpp"
#include "client_options.hpp"
#include "commands.hpp"
#include "console_server.hpp"

namespace adit::tools {
namespace {

struct CmdOptions {
  ClientOptions client;
  std::string listen = "0.0.0.0:8080";
  std::string config_file;
  std::string sessions_dir;
  std::string data_dir = "adit-console";
  std::string web_dir;
  std::string three_dir = "/usr/share/javascript/three";
  std::string passphrase_file;
  bool hash_passphrase = false;
};

// The web app installed beside the binary: <prefix>/bin/adit -> <prefix>/share/adit/console
// (the build tree has the same layout).
std::filesystem::path default_web_dir() {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path("share/adit/console") : exe.parent_path().parent_path() / "share/adit/console";
}

std::pair<std::string, int> parse_listen(const std::string& text) {
  const std::size_t colon = text.rfind(':');
  const auto bad = [&] { return InputError("--listen", "listen", fmt::format("'{}' is not ADDR:PORT", text)); };
  if (colon == std::string::npos || colon == 0) throw bad();
  try {
    std::size_t used = 0;
    const int port = std::stoi(text.substr(colon + 1), &used);
    if (used != text.size() - colon - 1 || port < 1 || port > 65535) throw bad();
    return {text.substr(0, colon), port};
  } catch (const std::logic_error&) {
    throw bad();
  }
}

int run_console(const CmdOptions& o, const CLI::App& sub) {
  if (o.hash_passphrase) {
    std::string passphrase;
    std::getline(std::cin, passphrase);
    if (passphrase.empty()) throw InputError("stdin", "passphrase", "the passphrase is empty");
    fmt::print("{}\n", console::format_hash(console::hash_passphrase(passphrase)));
    return kExitOk;
  }
  console::ConsoleOptions options;
  options.client = o.client;
  if (!o.config_file.empty()) {
    // The payload's own configuration: its id, its LCM network and its sessions folder,
    // unless given on the command line.
    const config::Config payload = config::load_config(o.config_file);
    if (sub.count("--payload") == 0) options.client.payload_id = payload.payload.id;
    if (sub.count("--lcm-url") == 0) options.client.lcm_url = payload.lcm.url;
    options.sessions_dir = std::filesystem::path(payload.payload.state_dir) / "sessions";
  }
  if (!o.sessions_dir.empty()) options.sessions_dir = o.sessions_dir;
  std::tie(options.host, options.port) = parse_listen(o.listen);
  options.web_dir = o.web_dir.empty() ? default_web_dir() : std::filesystem::path(o.web_dir);
  options.three_dir = o.three_dir;
  options.data_dir = o.data_dir;
  if (!o.passphrase_file.empty()) options.passphrase = console::read_hash_file(o.passphrase_file);

  // SIGINT/SIGTERM are taken by one thread (sigwait), as aditd does; the
  // server's threads inherit the blocked mask.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::atomic<bool> stop{false};
  std::thread waiter([&] {
    while (!stop) {
      const timespec tick{0, 200'000'000};
      const int signal = sigtimedwait(&signals, nullptr, &tick);
      if (signal == SIGINT || signal == SIGTERM) stop = true;
    }
  });
  int status = kExitFailure;
  try {
    status = console::serve_console(options, stop);
  } catch (...) {
    stop = true;
    waiter.join();
    throw;
  }
  stop = true;
  waiter.join();
  return status;
}

}  // namespace

void register_console_commands(CLI::App& app, int& status) {
  auto o = std::make_shared<CmdOptions>();
  CLI::App* sub = app.add_subcommand("console", "Serve the tablet's web app: live view, health, start/stop, downloads");
  add_client_options(*sub, o->client);
  sub->add_option("--listen", o->listen, "HTTP address and port")->capture_default_str();
  sub->add_option("--config", o->config_file,
                  "The payload's aditd configuration: payload id, LCM URL and sessions folder from it")
      ->check(CLI::ExistingFile);
  sub->add_option("--sessions-dir", o->sessions_dir,
                  "The payload's sessions folder, when the console runs on the payload (trajectories, summaries)");
  sub->add_option("--data-dir", o->data_dir, "Where the console keeps downloaded maps and scan names")
      ->capture_default_str();
  sub->add_option("--web-dir", o->web_dir, "The web app's files (default: ../share/adit/console beside the binary)");
  sub->add_option("--three-dir", o->three_dir, "Folder of three.module.js (Debian: libjs-three)")
      ->capture_default_str();
  sub->add_option("--passphrase-file", o->passphrase_file,
                  "Operator passphrase hash (adit console --hash-passphrase): browsers must unlock to start/stop")
      ->check(CLI::ExistingFile);
  sub->add_flag("--hash-passphrase", o->hash_passphrase,
                "Read a passphrase from stdin, print the line for --passphrase-file and exit");
  sub->callback([o, sub, &status] { status = run_console(*o, *sub); });
}

}  // namespace adit::tools
