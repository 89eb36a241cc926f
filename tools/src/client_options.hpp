#pragma once
// Options every protocol command of `adit` shares: which payload, which LCM
// network, how long to wait for an answer.

#include <CLI/CLI.hpp>

#include <string>

#include "adit/protocol/channels.hpp"
#include "lcm_client.hpp"

namespace adit::tools {

inline void add_client_options(CLI::App& command, ClientOptions& options) {
  options.lcm_url = std::string(protocol::kDefaultLcmUrl);
  options.payload_id = "adit";
  command.add_option("--payload", options.payload_id, "Payload id to talk to (channel prefix ADIT/<id>/)")
      ->capture_default_str();
  command.add_option("--lcm-url", options.lcm_url, "LCM URL (ttl=1 reaches the local network, ttl=0 this host)")
      ->capture_default_str();
  command.add_option("--timeout", options.timeout_s, "Seconds to wait for the payload to answer")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  command.add_option("--key", options.key_file,
                     "Key file (adit keygen, mode 0600): sign every command for a payload that requires it");
}

}  // namespace adit::tools
