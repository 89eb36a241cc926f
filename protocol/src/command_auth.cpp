#include "adit/protocol/command_auth.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <sodium.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::protocol {
namespace {

constexpr std::string_view kDomain = "adit-command-v1";
constexpr std::string_view kKeyIdDomain = "adit-command-key-id";

void ensure_sodium() {
  // Idempotent and thread-safe; only fails when no random source exists.
  if (sodium_init() < 0) throw std::runtime_error("libsodium cannot initialise (no random source?)");
}

// Byte by byte: GCC 12 misreads vector::insert of a range here (-Wstringop-overflow).
template <typename Range>
void put_bytes(std::vector<std::uint8_t>& out, const Range& bytes) {
  for (const auto b : bytes) out.push_back(static_cast<std::uint8_t>(b));
}

void put_u64(std::vector<std::uint8_t>& out, std::uint64_t v) {
  for (int shift = 56; shift >= 0; shift -= 8) out.push_back(static_cast<std::uint8_t>(v >> shift));
}
void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<std::uint8_t>(v >> shift));
}
void put_string(std::vector<std::uint8_t>& out, const std::string& s) {
  put_u32(out, static_cast<std::uint32_t>(s.size()));
  put_bytes(out, s);
}

using Tag = std::array<std::uint8_t, kTagBytes>;

Tag compute_tag(const command_t& command, const CommandKey& key) {
  const std::vector<std::uint8_t> bytes = canonical_command_bytes(command, key.id());
  Tag tag{};
  crypto_auth_hmacsha256(tag.data(), bytes.data(), bytes.size(), key.secret().data());
  return tag;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

}  // namespace

CommandKey::CommandKey(std::span<const std::uint8_t, kCommandKeyBytes> secret) {
  ensure_sodium();
  std::copy(secret.begin(), secret.end(), secret_.begin());
  std::array<std::uint8_t, crypto_hash_sha256_BYTES> digest{};
  crypto_hash_sha256_state state;
  crypto_hash_sha256_init(&state);
  crypto_hash_sha256_update(&state, reinterpret_cast<const unsigned char*>(kKeyIdDomain.data()), kKeyIdDomain.size());
  crypto_hash_sha256_update(&state, secret_.data(), secret_.size());
  crypto_hash_sha256_final(&state, digest.data());
  std::copy_n(digest.begin(), kKeyIdBytes, id_.begin());
}

CommandKey::~CommandKey() { sodium_memzero(secret_.data(), secret_.size()); }
CommandKey::CommandKey(const CommandKey& other) = default;
CommandKey& CommandKey::operator=(const CommandKey& other) = default;

CommandKey CommandKey::generate() {
  ensure_sodium();
  std::array<std::uint8_t, kCommandKeyBytes> secret{};
  randombytes_buf(secret.data(), secret.size());
  CommandKey key{std::span<const std::uint8_t, kCommandKeyBytes>(secret)};
  sodium_memzero(secret.data(), secret.size());
  return key;
}

std::string key_id_hex(const KeyId& id) {
  std::string out;
  for (const std::uint8_t b : id) out += fmt::format("{:02x}", b);
  return out;
}

std::vector<std::uint8_t> canonical_command_bytes(const command_t& command, const KeyId& key_id) {
  std::vector<std::uint8_t> out;
  out.reserve(64 + command.payload_id.size() + command.verb.size());
  put_bytes(out, kDomain);
  put_bytes(out, key_id);
  out.push_back(kAuthSchemeHmacSha256);
  put_u64(out, static_cast<std::uint64_t>(command.utime));
  out.push_back(static_cast<std::uint8_t>(static_cast<std::uint16_t>(command.schema) >> 8));
  out.push_back(static_cast<std::uint8_t>(static_cast<std::uint16_t>(command.schema) & 0xff));
  put_u64(out, static_cast<std::uint64_t>(command.request_id));
  put_string(out, command.payload_id);
  put_string(out, command.verb);
  // n_args as the args actually present: a decoded command has them equal.
  put_u32(out, static_cast<std::uint32_t>(command.args.size()));
  for (const std::string& arg : command.args) put_string(out, arg);
  return out;
}

void sign_command(command_t& command, const CommandKey& key) {
  command.n_args = static_cast<std::int32_t>(command.args.size());
  const Tag tag = compute_tag(command, key);
  command.auth.clear();
  command.auth.push_back(kAuthSchemeHmacSha256);
  put_bytes(command.auth, key.id());
  put_bytes(command.auth, tag);
  command.auth_size = static_cast<std::int32_t>(command.auth.size());
}

std::string_view auth_verdict_name(AuthVerdict verdict) {
  switch (verdict) {
    case AuthVerdict::ok: return "ok";
    case AuthVerdict::unsigned_command: return "unsigned";
    case AuthVerdict::malformed: return "malformed tag";
    case AuthVerdict::unknown_key: return "unknown key";
    case AuthVerdict::bad_tag: return "bad tag";
  }
  return "?";
}

AuthCheck verify_command(const command_t& command, std::span<const CommandKey> keys) {
  AuthCheck check;
  if (command.auth.empty()) return check;
  if (command.auth.size() != kAuthBytes || command.auth[0] != kAuthSchemeHmacSha256 ||
      command.args.size() != static_cast<std::size_t>(std::max(0, command.n_args))) {
    check.verdict = AuthVerdict::malformed;
    return check;
  }
  std::copy_n(command.auth.begin() + 1, kKeyIdBytes, check.key_id.begin());
  const auto key = std::find_if(keys.begin(), keys.end(), [&](const CommandKey& k) { return k.id() == check.key_id; });
  if (key == keys.end()) {
    check.verdict = AuthVerdict::unknown_key;
    return check;
  }
  const std::vector<std::uint8_t> bytes = canonical_command_bytes(command, key->id());
  const std::uint8_t* tag = command.auth.data() + 1 + kKeyIdBytes;
  check.verdict = crypto_auth_hmacsha256_verify(tag, bytes.data(), bytes.size(), key->secret().data()) == 0
                      ? AuthVerdict::ok
                      : AuthVerdict::bad_tag;
  return check;
}

std::vector<CommandKey> parse_key_file(std::string_view text, const std::string& source) {
  ensure_sodium();
  std::vector<CommandKey> keys;
  std::size_t line_number = 0;
  while (!text.empty()) {
    ++line_number;
    const std::size_t end = std::min(text.find('\n'), text.size());
    const std::string_view line = trim(text.substr(0, end));
    text.remove_prefix(std::min(end + 1, text.size()));
    if (line.empty() || line.front() == '#') continue;
    const std::string where = fmt::format("{}:{}", source, line_number);
    const std::size_t space = line.find_first_of(" \t");
    const std::string_view word = line.substr(0, space);
    if (word != kKeyFileWord)
      throw InputError(where, "key", fmt::format("expected '{} <64 hex digits>', found '{}'", kKeyFileWord, word));
    const std::string_view hex = space == std::string_view::npos ? std::string_view{} : trim(line.substr(space));
    std::array<std::uint8_t, kCommandKeyBytes> secret{};
    std::size_t decoded = 0;
    const char* hex_end = nullptr;
    if (hex.size() != 2 * kCommandKeyBytes ||
        sodium_hex2bin(secret.data(), secret.size(), hex.data(), hex.size(), nullptr, &decoded, &hex_end) != 0 ||
        decoded != kCommandKeyBytes || hex_end != hex.data() + hex.size()) {
      sodium_memzero(secret.data(), secret.size());
      throw InputError(where, "key", fmt::format("the key must be {} hex digits (a {}-byte key)",
                                                 2 * kCommandKeyBytes, kCommandKeyBytes));
    }
    keys.emplace_back(std::span<const std::uint8_t, kCommandKeyBytes>(secret));
    sodium_memzero(secret.data(), secret.size());
  }
  if (keys.empty()) throw InputError(source, "key", fmt::format("no key in the file (expected a line '{} <hex>')", kKeyFileWord));
  return keys;
}

std::vector<CommandKey> read_key_file(const std::filesystem::path& path) {
  const std::string name = path.string();
  const int fd = ::open(name.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) throw InputError(name, "key", fmt::format("cannot open the key file: {}", std::strerror(errno)));
  struct stat st {};
  std::string text;
  const bool stat_ok = ::fstat(fd, &st) == 0;
  if (stat_ok && S_ISREG(st.st_mode) && (st.st_mode & (S_IRWXG | S_IRWXO)) == 0 && st.st_size <= 64 * 1024) {
    text.resize(static_cast<std::size_t>(st.st_size));
    std::size_t have = 0;
    while (have < text.size()) {
      const ssize_t n = ::read(fd, text.data() + have, text.size() - have);
      if (n <= 0) break;
      have += static_cast<std::size_t>(n);
    }
    text.resize(have);
  }
  ::close(fd);
  if (!stat_ok) throw InputError(name, "key", "cannot stat the key file");
  if (!S_ISREG(st.st_mode)) throw InputError(name, "key", "the key file is not a regular file");
  if ((st.st_mode & (S_IRWXG | S_IRWXO)) != 0)
    throw InputError(name, "key",
                     fmt::format("the key file has mode {:04o}: group or others may use it; only its owner may "
                                 "(chmod 600 {})",
                                 st.st_mode & 07777, name));
  if (st.st_size > 64 * 1024) throw InputError(name, "key", "the key file is larger than 64 KB");
  std::vector<CommandKey> keys = parse_key_file(text, name);
  sodium_memzero(text.data(), text.size());
  return keys;
}

std::string format_key_file(const CommandKey& key) {
  std::array<char, 2 * kCommandKeyBytes + 1> hex{};
  sodium_bin2hex(hex.data(), hex.size(), key.secret().data(), key.secret().size());
  std::string text = fmt::format(
      "# adit command key (HMAC-SHA-256, docs/PROTOCOL.md); key id {}\n"
      "# Secret: keep this file mode 0600, on the payload and the clients that may command it.\n"
      "{} {}\n",
      key_id_hex(key.id()), kKeyFileWord, hex.data());
  sodium_memzero(hex.data(), hex.size());
  return text;
}

void write_key_file(const std::filesystem::path& path, const CommandKey& key, bool replace) {
  const std::string name = path.string();
  const std::string target = replace ? name + ".new" : name;
  if (replace) ::unlink(target.c_str());
  const int fd = ::open(target.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0600);
  if (fd < 0)
    throw InputError(name, "out",
                     errno == EEXIST ? std::string("the file exists: refusing to replace a key (--force replaces it)")
                                     : fmt::format("cannot create the key file: {}", std::strerror(errno)));
  std::string text = format_key_file(key);
  // The umask may only remove bits; make the mode exact whatever it was.
  bool ok = ::fchmod(fd, 0600) == 0;
  ok = ok && ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  ok = ::fsync(fd) == 0 && ok;
  ok = ::close(fd) == 0 && ok;
  sodium_memzero(text.data(), text.size());
  if (!ok) {
    ::unlink(target.c_str());
    throw InputError(name, "out", fmt::format("cannot write the key file: {}", std::strerror(errno)));
  }
  if (replace && ::rename(target.c_str(), name.c_str()) != 0) {
    ::unlink(target.c_str());
    throw InputError(name, "out", fmt::format("cannot replace the key file: {}", std::strerror(errno)));
  }
}

}  // namespace adit::protocol
