#pragma once
// Command authentication (docs/COMMAND-AUTH.md,
// docs/decisions/023-command-authentication.md): HMAC-SHA-256 with a
// pre-shared 32-byte key over a canonical encoding of every field of a
// command_t but the tag itself. This file is the pure part: canonical bytes,
// sign, verify, key files. Freshness (the time window) and replays are judged
// by the CommandGate; nothing here touches sockets or clocks.
//
// auth[] of a signed command (41 bytes):
//   byte 0      scheme, 1 = HMAC-SHA-256 v1
//   bytes 1-8   key id: the first 8 bytes of SHA-256("adit-command-key-id" || key)
//   bytes 9-40  tag = HMAC-SHA-256(key, canonical_command_bytes(command, key id))
//
// canonical_command_bytes (all integers big-endian, strings as u32 length + bytes):
//   "adit-command-v1" (15 bytes, no length) || key id (8) || scheme (1) ||
//   utime (i64) || schema (i16) || request_id (i64) || payload_id (str) ||
//   verb (str) || n_args (i32) || args[0..n_args) (str each)

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "adit/command_t.hpp"

namespace adit::protocol {

inline constexpr std::uint8_t kAuthSchemeHmacSha256 = 1;
inline constexpr std::size_t kCommandKeyBytes = 32;
inline constexpr std::size_t kKeyIdBytes = 8;
inline constexpr std::size_t kTagBytes = 32;
inline constexpr std::size_t kAuthBytes = 1 + kKeyIdBytes + kTagBytes;
// The first word of a key file line.
inline constexpr std::string_view kKeyFileWord = "adit-command-key-v1";

using KeyId = std::array<std::uint8_t, kKeyIdBytes>;

// A secret key and its public id. The secret is wiped when the key goes.
class CommandKey {
 public:
  explicit CommandKey(std::span<const std::uint8_t, kCommandKeyBytes> secret);
  ~CommandKey();
  CommandKey(const CommandKey& other);
  CommandKey& operator=(const CommandKey& other);

  // 32 bytes from the system's random source (libsodium's randombytes).
  static CommandKey generate();

  const KeyId& id() const { return id_; }
  std::span<const std::uint8_t, kCommandKeyBytes> secret() const { return secret_; }

 private:
  std::array<std::uint8_t, kCommandKeyBytes> secret_{};
  KeyId id_{};
};

std::string key_id_hex(const KeyId& id);

// The bytes the tag covers (layout above).
std::vector<std::uint8_t> canonical_command_bytes(const command_t& command, const KeyId& key_id);

// Fills auth/auth_size; every other field must be final before.
void sign_command(command_t& command, const CommandKey& key);

enum class AuthVerdict {
  ok,
  unsigned_command,  // auth[] empty
  malformed,         // auth[] not 41 bytes or unknown scheme
  unknown_key,       // key id of no key held
  bad_tag            // the tag does not match the content
};
std::string_view auth_verdict_name(AuthVerdict verdict);

struct AuthCheck {
  AuthVerdict verdict = AuthVerdict::unsigned_command;
  KeyId key_id{};  // as carried by the command (when it has one)
};
// Constant-time comparison of the tag (crypto_auth_hmacsha256_verify).
AuthCheck verify_command(const command_t& command, std::span<const CommandKey> keys);

// Key files: text, '#' comments and blank lines ignored, one key per line:
//   adit-command-key-v1 <64 hex digits>
// The first key signs (clients); a payload accepts every key listed, so a new
// key can be added before the old one is removed (rotation).
// Throws InputError naming `source`:line for a bad line, or no key at all.
std::vector<CommandKey> parse_key_file(std::string_view text, const std::string& source);
// Reads and parses a key file; refuses (InputError) a file that is not a
// regular file or that its group or others may read, write or run.
std::vector<CommandKey> read_key_file(const std::filesystem::path& path);
std::string format_key_file(const CommandKey& key);
// Writes a new key file with mode 0600; refuses to replace an existing file
// unless `replace` (then writes a temporary file and renames it over).
void write_key_file(const std::filesystem::path& path, const CommandKey& key, bool replace);

}  // namespace adit::protocol
