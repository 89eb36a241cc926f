// Fuzzes what adit console reads from outside: the passphrase file's line and
// a browser's Last-Event-ID header. Either is accepted or refused with an
// InputError / nullopt, never a crash.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "adit/common/error.hpp"
#include "console_events.hpp"
#include "console_passphrase.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    (void)adit::tools::console::parse_hash_line(text, "fuzz:1");
  } catch (const adit::InputError&) {
  }
  (void)adit::tools::console::resume_after(text, "3f2a91c");
  return 0;
}
