// The cost of checking one command's tag, for decision 022: what the LCM
// endpoint's thread spends per forged command in a flood. The gate's own
// check (decode + HMAC-SHA-256 verification, what ships) against the
// alternative that was not chosen, an Ed25519 signature over the same
// canonical bytes (libsodium), in the same run.
#include <benchmark/benchmark.h>

#include <sodium.h>

#include <array>
#include <vector>

#include "adit/protocol/command_auth.hpp"
#include "adit/protocol/command_gate.hpp"

namespace {

using namespace adit;

constexpr std::int64_t kNow = 1'795'000'000'000'000;

protocol::CommandKey bench_key() {
  std::array<std::uint8_t, protocol::kCommandKeyBytes> secret{};
  secret.fill(7);
  return protocol::CommandKey(std::span<const std::uint8_t, protocol::kCommandKeyBytes>(secret));
}

command_t bench_command() {
  command_t c;
  c.utime = kNow;
  c.schema = 1;
  c.request_id = 42;
  c.payload_id = "payload-01";
  c.verb = "START";
  c.args = {"name=north-drift"};
  c.n_args = 1;
  c.auth_size = 0;
  return c;
}

std::vector<std::uint8_t> encoded(const command_t& c) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(c.getEncodedSize()));
  c.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

// A forged command (right key id, wrong tag) through the gate: decode,
// canonical bytes, HMAC-SHA-256 verification, rejection.
void BM_GateRejectsForgedHmac(benchmark::State& state) {
  command_t c = bench_command();
  protocol::sign_command(c, bench_key());
  c.auth.back() ^= 1;
  const std::vector<std::uint8_t> bytes = encoded(c);
  protocol::CommandGate gate("payload-01");
  gate.set_keys({bench_key()}, 30'000'000);
  for (auto _ : state) {
    const protocol::GateResult r = gate.inspect(bytes.data(), bytes.size(), kNow);
    benchmark::DoNotOptimize(r.kind);
  }
}
BENCHMARK(BM_GateRejectsForgedHmac);

// The same decode and canonical bytes, checked as an Ed25519 signature.
void BM_DecodeAndVerifyEd25519(benchmark::State& state) {
  if (sodium_init() < 0) state.SkipWithError("libsodium");
  std::array<unsigned char, crypto_sign_PUBLICKEYBYTES> pk{};
  std::array<unsigned char, crypto_sign_SECRETKEYBYTES> sk{};
  crypto_sign_keypair(pk.data(), sk.data());
  command_t c = bench_command();
  const auto canonical = protocol::canonical_command_bytes(c, bench_key().id());
  std::array<unsigned char, crypto_sign_BYTES> signature{};
  crypto_sign_detached(signature.data(), nullptr, canonical.data(), canonical.size(), sk.data());
  signature[5] ^= 1;  // forged
  c.auth.assign(signature.begin(), signature.end());
  c.auth_size = static_cast<std::int32_t>(c.auth.size());
  const std::vector<std::uint8_t> bytes = encoded(c);
  for (auto _ : state) {
    command_t decoded;
    decoded.decode(bytes.data(), 0, static_cast<int>(bytes.size()));
    const auto message = protocol::canonical_command_bytes(decoded, bench_key().id());
    const int ok = crypto_sign_verify_detached(decoded.auth.data(), message.data(), message.size(), pk.data());
    benchmark::DoNotOptimize(ok);
  }
}
BENCHMARK(BM_DecodeAndVerifyEd25519);

}  // namespace

BENCHMARK_MAIN();
