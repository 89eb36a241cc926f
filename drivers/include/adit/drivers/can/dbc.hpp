#pragma once
// A DBC file's messages (BO_) and signals (SG_), with SIG_VALTYPE_ for float
// signals. Everything else (nodes, comments, attributes, value tables) is
// skipped. Multiplexed signals (M / mN) are read and marked.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "adit/drivers/can/signal.hpp"

namespace adit::drivers::can {

struct Database {
  std::vector<MessageSpec> messages;

  const MessageSpec* find(std::string_view name) const;
  const MessageSpec* find(std::uint32_t id, bool extended) const;
};

// Throws adit::InputError("source:line", "BO_"/"SG_"/..., reason) on a
// malformed message or signal line, or a signal that does not fit its message.
Database parse_dbc(std::string_view text, const std::string& source);
Database load_dbc(const std::filesystem::path& file);

}  // namespace adit::drivers::can
