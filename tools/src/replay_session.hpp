#pragma once
// `adit replay --session DIR`: a stored session mapped again from its raw
// recordings (lidar.pcap, can.log) with the configuration it ran with
// (config.yaml), by aditd's own session code: a new session folder with its
// map, trajectory and summary (docs/SESSIONS.md).

#include <filesystem>

namespace adit::tools {

// Writes the new session under `out_dir`/sessions/<id>/; prints its folder
// and figures; returns the exit status. Throws adit::InputError naming a
// missing recording or configuration.
int replay_session(const std::filesystem::path& session_dir, const std::filesystem::path& out_dir);

}  // namespace adit::tools
