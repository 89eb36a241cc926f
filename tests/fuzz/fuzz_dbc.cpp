// Fuzzes the DBC parser and the decoder built from what it accepts: any input
// must load or be rejected with adit::InputError; decoding never crashes.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "adit/common/error.hpp"
#include "adit/drivers/can/dbc.hpp"
#include "adit/drivers/can/decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace can = adit::drivers::can;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const can::Database db = can::parse_dbc(text, "fuzz.dbc");
    can::SignalDecoder decoder(db.messages);
    std::vector<double> values(decoder.slot_count());
    for (const can::MessageSpec& m : db.messages) {
      can::Frame f;
      f.id = m.id;
      f.extended = m.extended;
      f.length = static_cast<std::uint8_t>(std::min<unsigned>(m.length, 64));
      f.fd = f.length > 8;
      std::copy_n(data, std::min<std::size_t>(size, f.length), f.data.begin());
      decoder.decode(f, values);
    }
  } catch (const adit::InputError&) {
  }
  return 0;
}
