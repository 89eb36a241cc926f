#include "console_passphrase.hpp"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/rand.h>

#include <charconv>
#include <fstream>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::tools::console {
namespace {

std::string random_bytes(std::size_t n) {
  std::string out(n, '\0');
  if (RAND_bytes(reinterpret_cast<unsigned char*>(out.data()), static_cast<int>(n)) != 1)
    throw std::runtime_error("no random bytes from OpenSSL");
  return out;
}

std::string to_hex(const std::string& bytes) {
  std::string out;
  for (const unsigned char c : bytes) out += fmt::format("{:02x}", c);
  return out;
}

std::optional<std::string> from_hex(const std::string& hex) {
  if (hex.size() % 2 != 0 || hex.empty()) return std::nullopt;
  std::string out;
  for (std::size_t i = 0; i < hex.size(); i += 2) {
    unsigned value = 0;
    for (std::size_t k = 0; k < 2; ++k) {
      const char c = hex[i + k];
      const int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
      if (d < 0) return std::nullopt;
      value = value * 16 + static_cast<unsigned>(d);
    }
    out.push_back(static_cast<char>(value));
  }
  return out;
}

std::string derive(const std::string& passphrase, const std::string& salt, std::uint32_t iterations) {
  std::string out(32, '\0');
  if (PKCS5_PBKDF2_HMAC(passphrase.data(), static_cast<int>(passphrase.size()),
                        reinterpret_cast<const unsigned char*>(salt.data()), static_cast<int>(salt.size()),
                        static_cast<int>(iterations), EVP_sha256(), static_cast<int>(out.size()),
                        reinterpret_cast<unsigned char*>(out.data())) != 1)
    throw std::runtime_error("PBKDF2 failed in OpenSSL");
  return out;
}

}  // namespace

PassphraseHash hash_passphrase(const std::string& passphrase, std::uint32_t iterations) {
  PassphraseHash h{iterations, random_bytes(16), {}};
  h.hash = derive(passphrase, h.salt, iterations);
  return h;
}

std::string format_hash(const PassphraseHash& h) {
  return fmt::format("pbkdf2-sha256${}${}${}", h.iterations, to_hex(h.salt), to_hex(h.hash));
}

PassphraseHash parse_hash_line(std::string_view line, const std::string& where) {
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.remove_suffix(1);
  const auto bad = [&](const std::string& why) { return InputError(where, "passphrase-file", why); };
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (std::size_t at = line.find('$'); at != std::string_view::npos; at = line.find('$', start)) {
    parts.emplace_back(line.substr(start, at - start));
    start = at + 1;
  }
  parts.emplace_back(line.substr(start));
  if (parts.size() != 4 || parts[0] != "pbkdf2-sha256")
    throw bad("not a 'pbkdf2-sha256$<iterations>$<salt hex>$<hash hex>' line (adit console --hash-passphrase)");
  PassphraseHash h;
  unsigned long n = 0;
  const auto [end, error] = std::from_chars(parts[1].data(), parts[1].data() + parts[1].size(), n);
  if (error != std::errc() || end != parts[1].data() + parts[1].size() || parts[1].empty())
    throw bad(fmt::format("iterations '{}' is not a number", parts[1]));
  if (n < 1000 || n > 100'000'000) throw bad(fmt::format("iterations {} outside 1000..100000000", n));
  h.iterations = static_cast<std::uint32_t>(n);
  const auto salt = from_hex(parts[2]);
  const auto hash = from_hex(parts[3]);
  if (!salt || salt->size() < 8) throw bad("the salt is not at least 8 bytes of hex");
  if (!hash || hash->size() != 32) throw bad("the hash is not 32 bytes of hex");
  h.salt = *salt;
  h.hash = *hash;
  return h;
}

PassphraseHash read_hash_file(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), "passphrase-file", "cannot be read");
  std::string line;
  std::getline(in, line);
  return parse_hash_line(line, fmt::format("{}:1", file.string()));
}

bool passphrase_matches(const PassphraseHash& h, const std::string& passphrase) {
  const std::string got = derive(passphrase, h.salt, h.iterations);
  return got.size() == h.hash.size() && CRYPTO_memcmp(got.data(), h.hash.data(), got.size()) == 0;
}

std::optional<std::string> ControlGate::unlock(const std::string& passphrase) {
  if (!hash_) return std::string();
  if (!passphrase_matches(*hash_, passphrase)) return std::nullopt;
  std::string token = to_hex(random_bytes(24));
  const std::lock_guard lock(mutex_);
  const auto now = std::chrono::steady_clock::now();
  std::erase_if(tokens_, [&](const auto& t) { return t.second < now; });
  tokens_[token] = now + token_life_;
  return token;
}

bool ControlGate::allows(const std::string& token) const {
  if (!hash_) return true;
  const std::lock_guard lock(mutex_);
  const auto it = tokens_.find(token);
  return it != tokens_.end() && it->second >= std::chrono::steady_clock::now();
}

}  // namespace adit::tools::console
