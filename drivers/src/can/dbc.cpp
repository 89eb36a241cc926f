// DBC reading. Grammar of the lines we use (Vector "DBC File Format
// Documentation" v1.0.5, sections 8.1 and 8.2, 10 for SIG_VALTYPE_):
//   BO_ <id> <name>: <length> <sender>
//    SG_ <name> [M|m<n>] : <start>|<length>@<0|1><+|-> (<factor>,<offset>) [<min>|<max>] "<unit>" <receivers>
//   SIG_VALTYPE_ <id> <name> : <0|1|2>;
// Bit 31 of a BO_ id marks a 29-bit identifier.

#include "adit/drivers/can/dbc.hpp"

#include <charconv>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::drivers::can {
namespace {

constexpr std::uint32_t kDbcExtendedBit = 0x80000000U;

// A cursor over one line; every reader skips leading blanks first.
class Cursor {
 public:
  explicit Cursor(std::string_view s) : s_(s) {}
  void skip_blanks() {
    while (!s_.empty() && (s_.front() == ' ' || s_.front() == '\t' || s_.front() == '\r')) s_.remove_prefix(1);
  }
  bool eat(char c) {
    skip_blanks();
    if (s_.empty() || s_.front() != c) return false;
    s_.remove_prefix(1);
    return true;
  }
  // An identifier-like word: up to a blank or one of `stops`.
  std::string_view word(std::string_view stops = "") {
    skip_blanks();
    std::size_t n = 0;
    while (n < s_.size() && s_[n] != ' ' && s_[n] != '\t' && s_[n] != '\r' && stops.find(s_[n]) == std::string_view::npos) ++n;
    const std::string_view w = s_.substr(0, n);
    s_.remove_prefix(n);
    return w;
  }
  template <typename T>
  bool number(T& out) {
    skip_blanks();
    const char* begin = s_.data();
    const char* end = begin + s_.size();
    if (begin != end && *begin == '+') ++begin;  // from_chars rejects a leading '+'
    const auto [ptr, ec] = std::from_chars(begin, end, out);
    if (ec != std::errc{}) return false;
    s_.remove_prefix(static_cast<std::size_t>(ptr - s_.data()));
    return true;
  }
  bool quoted(std::string& out) {
    if (!eat('"')) return false;
    const std::size_t end = s_.find('"');
    if (end == std::string_view::npos) return false;
    out.assign(s_.substr(0, end));
    s_.remove_prefix(end + 1);
    return true;
  }
  std::string_view rest() const { return s_; }

 private:
  std::string_view s_;
};

// Bit positions a signal occupies, as the lowest and highest byte touched.
bool signal_bytes(const SignalSpec& s, unsigned& first, unsigned& last) {
  if (s.length == 0 || s.length > 64 || s.start_bit >= 8 * 64) return false;
  if (s.byte_order == ByteOrder::intel) {
    first = s.start_bit / 8;
    last = (s.start_bit + s.length - 1) / 8;
  } else {
    // Motorola: start bit is the MSB; in a big-endian bit stream (bit 0 = MSB of
    // byte 0) it is at msb, and the signal runs to msb + length - 1.
    const unsigned msb = (s.start_bit / 8) * 8 + 7 - s.start_bit % 8;
    first = msb / 8;
    last = (msb + s.length - 1) / 8;
  }
  return true;
}

[[noreturn]] void fail(const std::string& source, std::size_t line, const char* key, const std::string& why) {
  throw InputError(fmt::format("{}:{}", source, line), key, why);
}

SignalSpec parse_signal(Cursor& c, const std::string& source, std::size_t line) {
  SignalSpec s;
  s.name = std::string(c.word(":"));
  if (s.name.empty()) fail(source, line, "SG_", "signal without a name");
  if (!c.eat(':')) {
    const std::string_view mux = c.word(":");
    if (mux == "M") {
      s.multiplex = Multiplex::selector;
    } else if (mux.size() >= 2 && mux.front() == 'm') {
      // "m3" or "m3M" (extended multiplexing, which we treat as plain mN)
      unsigned v = 0;
      const auto [ptr, ec] = std::from_chars(mux.data() + 1, mux.data() + mux.size(), v);
      if (ec != std::errc{}) fail(source, line, "SG_", fmt::format("bad multiplexer '{}' of {}", mux, s.name));
      (void)ptr;
      s.multiplex = Multiplex::multiplexed;
      s.multiplex_value = v;
    } else {
      fail(source, line, "SG_", fmt::format("expected ':' after signal {}", s.name));
    }
    if (!c.eat(':')) fail(source, line, "SG_", fmt::format("expected ':' after signal {}", s.name));
  }
  int order = 0;
  if (!c.number(s.start_bit) || !c.eat('|') || !c.number(s.length) || !c.eat('@') || !c.number(order) ||
      (order != 0 && order != 1))
    fail(source, line, "SG_", fmt::format("signal {}: expected <start>|<length>@<0|1>", s.name));
  s.byte_order = order == 1 ? ByteOrder::intel : ByteOrder::motorola;
  if (c.eat('-')) {
    s.is_signed = true;
  } else if (!c.eat('+')) {
    fail(source, line, "SG_", fmt::format("signal {}: expected sign '+' or '-'", s.name));
  }
  if (!c.eat('(') || !c.number(s.factor) || !c.eat(',') || !c.number(s.offset) || !c.eat(')'))
    fail(source, line, "SG_", fmt::format("signal {}: expected (<factor>,<offset>)", s.name));
  if (!c.eat('[') || !c.number(s.minimum) || !c.eat('|') || !c.number(s.maximum) || !c.eat(']'))
    fail(source, line, "SG_", fmt::format("signal {}: expected [<min>|<max>]", s.name));
  if (!c.quoted(s.unit)) fail(source, line, "SG_", fmt::format("signal {}: expected \"<unit>\"", s.name));
  if (s.length == 0 || s.length > 64) fail(source, line, "SG_", fmt::format("signal {}: length {} not in 1..64", s.name, s.length));
  return s;
}

void check_fits(const MessageSpec& m, const SignalSpec& s, const std::string& source, std::size_t line) {
  unsigned first = 0;
  unsigned last = 0;
  if (!signal_bytes(s, first, last) || last >= m.length)
    fail(source, line, "SG_",
         fmt::format("signal {} (start {}, length {}) does not fit message {} of {} bytes", s.name, s.start_bit,
                     s.length, m.name, m.length));
}

}  // namespace

const MessageSpec* Database::find(std::string_view name) const {
  for (const MessageSpec& m : messages)
    if (m.name == name) return &m;
  return nullptr;
}

const MessageSpec* Database::find(std::uint32_t id, bool extended) const {
  for (const MessageSpec& m : messages)
    if (m.id == id && m.extended == extended) return &m;
  return nullptr;
}

Database parse_dbc(std::string_view text, const std::string& source) {
  Database db;
  MessageSpec* current = nullptr;
  std::size_t line_no = 0;
  bool skipping = false;
  while (!text.empty()) {
    const std::size_t eol = text.find('\n');
    const std::string_view line = text.substr(0, eol);
    text.remove_prefix(eol == std::string_view::npos ? text.size() : eol + 1);
    ++line_no;
    Cursor c(line);
    const std::string_view keyword = c.word(":");
    if (keyword == "BO_") {
      MessageSpec m;
      std::uint32_t raw_id = 0;
      if (!c.number(raw_id)) fail(source, line_no, "BO_", "expected a message id");
      m.name = std::string(c.word(":"));
      if (m.name.empty() || !c.eat(':') || !c.number(m.length))
        fail(source, line_no, "BO_", "expected BO_ <id> <name>: <length> <sender>");
      if (m.length > 64) fail(source, line_no, "BO_", fmt::format("message {}: length {} over 64", m.name, m.length));
      m.extended = (raw_id & kDbcExtendedBit) != 0;
      m.id = raw_id & ~kDbcExtendedBit;
      // Ids out of range (VECTOR__INDEPENDENT_SIG_MSG, 0xC0000000) hold signals
      // not sent by anyone: skip the message and its signals.
      skipping = m.id > (m.extended ? 0x1FFFFFFFU : 0x7FFU);
      if (skipping) continue;
      db.messages.push_back(std::move(m));
      current = &db.messages.back();
    } else if (keyword == "SG_") {
      if (skipping) continue;
      if (current == nullptr) fail(source, line_no, "SG_", "signal before any BO_ message");
      SignalSpec s = parse_signal(c, source, line_no);
      check_fits(*current, s, source, line_no);
      current->signals.push_back(std::move(s));
    } else if (keyword == "SIG_VALTYPE_" && !c.word().empty()) {  // a bare word lists it in NS_
      c = Cursor(line);
      c.word(":");
      std::uint32_t raw_id = 0;
      int type = 0;
      const bool ok = c.number(raw_id);
      const std::string_view name = c.word(":");
      if (!ok || name.empty() || !c.eat(':') || !c.number(type) || type < 0 || type > 2)
        fail(source, line_no, "SIG_VALTYPE_", "expected SIG_VALTYPE_ <id> <signal> : <0|1|2>;");
      MessageSpec* m = nullptr;
      for (MessageSpec& candidate : db.messages)
        if (candidate.id == (raw_id & ~kDbcExtendedBit) && candidate.extended == ((raw_id & kDbcExtendedBit) != 0)) m = &candidate;
      if (m == nullptr) fail(source, line_no, "SIG_VALTYPE_", fmt::format("no message with id {}", raw_id));
      bool found = false;
      for (SignalSpec& s : m->signals) {
        if (s.name != name) continue;
        const unsigned need = type == 1 ? 32 : 64;
        if (type != 0 && s.length != need)
          fail(source, line_no, "SIG_VALTYPE_", fmt::format("signal {}: float needs {} bits, has {}", s.name, need, s.length));
        s.type = type == 0 ? ValueType::integer : type == 1 ? ValueType::float32 : ValueType::float64;
        found = true;
      }
      if (!found) fail(source, line_no, "SIG_VALTYPE_", fmt::format("no signal {} in message {}", name, m->name));
    } else if (!keyword.empty()) {
      current = nullptr;  // SG_ lines belong to the BO_ right above them
      skipping = false;
    }
  }
  return db;
}

Database load_dbc(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot open DBC file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_dbc(text.str(), file.string());
}

}  // namespace adit::drivers::can
