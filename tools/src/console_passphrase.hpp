#pragma once
// adit console: the operator passphrase that unlocks control in the browser.
// The console stores only a salted PBKDF2-HMAC-SHA256 hash of it (RFC 8018,
// section 5.2), one line in a file: `pbkdf2-sha256$<iterations>$<salt hex>$<hash hex>`
// (`adit console --hash-passphrase` writes one). A browser that gives the
// passphrase gets a random token; commands that change state need a live token.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

namespace adit::tools::console {

struct PassphraseHash {
  std::uint32_t iterations = 0;
  std::string salt;  // raw bytes
  std::string hash;  // raw bytes, 32
};

// A new hash of `passphrase` with a random salt.
PassphraseHash hash_passphrase(const std::string& passphrase, std::uint32_t iterations = 200000);
std::string format_hash(const PassphraseHash& h);
// Throws InputError naming `where` when `line` is not one such line.
PassphraseHash parse_hash_line(std::string_view line, const std::string& where);
// Its first line; throws InputError naming `file` (and line 1) when it is not one.
PassphraseHash read_hash_file(const std::filesystem::path& file);
// Compares in constant time.
bool passphrase_matches(const PassphraseHash& h, const std::string& passphrase);

// Who may change state: nobody needs a token when no passphrase is set.
class ControlGate {
 public:
  explicit ControlGate(std::optional<PassphraseHash> hash, std::chrono::hours token_life = std::chrono::hours(12))
      : hash_(std::move(hash)), token_life_(token_life) {}
  bool locked() const { return hash_.has_value(); }
  // A token for a right passphrase (empty when no passphrase is set), nullopt otherwise.
  std::optional<std::string> unlock(const std::string& passphrase);
  bool allows(const std::string& token) const;

 private:
  std::optional<PassphraseHash> hash_;
  std::chrono::hours token_life_;
  mutable std::mutex mutex_;
  std::map<std::string, std::chrono::steady_clock::time_point> tokens_;  // token -> expiry
};

}  // namespace adit::tools::console
