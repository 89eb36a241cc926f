#pragma once
// adit console: the HTTP side. Serves the web app (static files and Debian's
// three.js), a JSON API and a Server-Sent Events stream of the live feed, the
// start/stop commands (through LcmClient::command, the path every `adit`
// command takes, so signing applies when it does), the session list and map
// downloads with Range. Routes and their answers: docs/CONSOLE.md.

#include <atomic>
#include <filesystem>
#include <optional>
#include <string>

#include "console_passphrase.hpp"
#include "lcm_client.hpp"

namespace adit::tools::console {

struct ConsoleOptions {
  ClientOptions client;
  std::string host = "0.0.0.0";
  int port = 8080;
  std::filesystem::path web_dir;       // index.html, app.js, style.css
  std::filesystem::path three_dir;     // three.module.js (Debian's libjs-three)
  std::filesystem::path data_dir;      // downloaded maps, scan names
  std::filesystem::path sessions_dir;  // the payload's sessions folder when on the payload ("" = none)
  std::optional<PassphraseHash> passphrase;
};

// Serves until `stop` becomes true; returns the exit status (2 when the
// address cannot be bound).
int serve_console(const ConsoleOptions& options, const std::atomic<bool>& stop);

}  // namespace adit::tools::console
