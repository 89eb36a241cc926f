#pragma once
// Errors that carry where bad input came from, so every program can print one
// line naming the file, the line and the key (or packet, or frame).

#include <stdexcept>
#include <string>

namespace adit {

// Exit statuses shared by every program: 2 means "your input is wrong" (bad
// option, bad config, bad file), as for nginx -t and most Unix tools.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitBadInput = 2;

// A problem with input the user gave us. `where` is "file:line" (or just the
// file when no line applies), `key` the dotted key or field name.
class InputError : public std::runtime_error {
 public:
  InputError(std::string where, std::string key, std::string what);

  const std::string& where() const { return where_; }
  const std::string& key() const { return key_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string where_;
  std::string key_;
  std::string reason_;
};

}  // namespace adit
