// adit can-decode: signals of a candump log decoded with a DBC, as CSV.
// adit can-info: what is on the bus: ids, rates, lengths, buses, errors.

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <fmt/os.h>

#include "adit/common/error.hpp"
#include "adit/drivers/can/bus_status.hpp"
#include "adit/drivers/can/candump.hpp"
#include "adit/drivers/can/dbc.hpp"
#include "adit/drivers/can/decoder.hpp"
#include "commands.hpp"

namespace adit::tools {
namespace {

namespace can = adit::drivers::can;

void report_malformed(const can::CandumpReader& reader) {
  for (const can::MalformedLine& e : reader.errors()) fmt::print(stderr, "warning: {}\n", reader.describe(e));
  if (reader.stats().malformed > reader.errors().size())
    fmt::print(stderr, "warning: {} more malformed lines\n", reader.stats().malformed - reader.errors().size());
}

struct DecodeOptions {
  std::string log;
  std::string dbc;
  std::vector<std::string> signals;
  std::string csv;
  std::string bus;
  bool physical = false;
};

can::SignalDecoder make_decoder(const can::Database& db, const DecodeOptions& o) {
  try {
    return can::SignalDecoder(db.messages, o.signals, !o.physical);
  } catch (const InputError& e) {
    throw InputError(o.dbc, e.key(), e.reason());  // name the DBC the signal is missing from
  }
}

int run_decode(const DecodeOptions& o) {
  const can::Database db = can::load_dbc(o.dbc);
  can::SignalDecoder decoder = make_decoder(db, o);
  can::CandumpReader reader(o.log);
  std::FILE* out = stdout;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(nullptr, &std::fclose);
  if (!o.csv.empty()) {
    file.reset(std::fopen(o.csv.c_str(), "w"));
    if (!file) throw InputError(o.csv, "--csv", "cannot create the CSV file");
    out = file.get();
  }
  // Wide CSV: one row per decoded frame, one column per selected signal;
  // columns of other messages stay empty.
  fmt::print(out, "t,interface,message");
  for (const can::DecodedSignal& s : decoder.signals())
    fmt::print(out, ",{}.{}{}", s.message, s.name, s.unit.empty() ? "" : fmt::format("[{}]", s.unit));
  fmt::print(out, "\n");
  std::vector<double> values(decoder.slot_count());
  std::string row;
  can::Frame f;
  while (reader.next(f)) {
    if (!o.bus.empty() && f.interface_name() != o.bus) continue;
    const can::DecodeResult r = decoder.decode(f, values);
    if (r.status != can::DecodeStatus::decoded) continue;
    row.clear();
    fmt::format_to(std::back_inserter(row), "{}.{:06d},{},{}", f.time_us / 1'000'000, f.time_us % 1'000'000,
                   f.interface_name(), decoder.signals()[r.first].message);
    for (std::uint32_t i = 0; i < decoder.slot_count(); ++i) {
      row.push_back(',');
      if (i >= r.first && i < r.first + r.count) fmt::format_to(std::back_inserter(row), "{}", values[i]);
    }
    row.push_back('\n');
    std::fputs(row.c_str(), out);
  }
  report_malformed(reader);
  const can::DecoderStats& s = decoder.stats();
  fmt::print(stderr, "{}: {} frames, {} decoded, {} of unknown id, {} of wrong length, {} error/remote, {} malformed lines\n",
             o.log, reader.stats().frames, s.decoded, s.unknown_id, s.wrong_length, s.not_data, reader.stats().malformed);
  return kExitOk;
}

struct IdKey {
  std::string interface;
  std::uint32_t id = 0;
  bool extended = false;
  bool operator<(const IdKey& o) const { return std::tie(interface, extended, id) < std::tie(o.interface, o.extended, o.id); }
};

struct IdSummary {
  std::uint64_t frames = 0;
  std::int64_t first_us = 0;
  std::int64_t last_us = 0;
  std::uint8_t min_length = 255;
  std::uint8_t max_length = 0;
  bool fd = false;
  std::uint64_t remote = 0;
};

struct BusSummary {
  std::uint64_t frames = 0;
  std::uint64_t fd = 0;
  std::int64_t first_us = 0;
  std::int64_t last_us = 0;
  can::BusMonitor monitor;
  can::BusState worst = can::BusState::ok;
};

int run_info(const std::string& log, const std::string& dbc_file) {
  can::Database db;
  if (!dbc_file.empty()) db = can::load_dbc(dbc_file);
  can::CandumpReader reader(log);
  std::map<IdKey, IdSummary> ids;
  std::map<std::string, BusSummary> buses;
  can::Frame f;
  while (reader.next(f)) {
    BusSummary& b = buses[std::string(f.interface_name())];
    if (b.frames++ == 0) b.first_us = f.time_us;
    b.last_us = f.time_us;
    b.fd += f.fd ? 1 : 0;
    b.worst = std::max(b.worst, b.monitor.on_frame(f));
    if (f.error) continue;
    IdSummary& s = ids[{std::string(f.interface_name()), f.id, f.extended}];
    if (s.frames++ == 0) s.first_us = f.time_us;
    s.last_us = f.time_us;
    s.min_length = std::min(s.min_length, f.length);
    s.max_length = std::max(s.max_length, f.length);
    s.fd |= f.fd;
    s.remote += f.remote ? 1 : 0;
  }
  fmt::print("{}: {} lines, {} frames, {} malformed lines\n", log, reader.stats().lines, reader.stats().frames,
             reader.stats().malformed);
  report_malformed(reader);
  for (const auto& [name, b] : buses) {
    const double span = static_cast<double>(b.last_us - b.first_us) * 1e-6;
    const can::BusCounters& c = b.monitor.counters();
    fmt::print("bus {}: {} frames over {:.3f} s ({:.0f} frames/s), {} FD, {} error frames "
               "(bus-off {}, error-passive {}, recoveries {}, no-ack {}, controller {}), state now {}, worst {}\n",
               name, b.frames, span, span > 0 ? static_cast<double>(b.frames) / span : 0.0, b.fd, c.error_frames,
               c.bus_off, c.error_passive, c.recoveries, c.no_ack, c.controller, can::bus_state_name(b.monitor.state()),
               can::bus_state_name(b.worst));
  }
  fmt::print("{:<8} {:>10} {:>9} {:>9} {:>7} {:>5}  {}\n", "bus", "id", "frames", "rate/Hz", "length", "kind", "message");
  for (const auto& [key, s] : ids) {
    const double span = static_cast<double>(s.last_us - s.first_us) * 1e-6;
    const double rate = s.frames > 1 && span > 0 ? static_cast<double>(s.frames - 1) / span : 0.0;
    const can::MessageSpec* m = db.find(key.id, key.extended);
    std::string length = s.min_length == s.max_length ? fmt::format("{}", s.min_length)
                                                      : fmt::format("{}-{}", s.min_length, s.max_length);
    if (m != nullptr && (s.min_length != m->length || s.max_length != m->length)) length += fmt::format("!={}", m->length);
    fmt::print("{:<8} {:>10} {:>9} {:>9.2f} {:>7} {:>5}  {}\n", key.interface,
               key.extended ? fmt::format("{:08X}", key.id) : fmt::format("{:03X}", key.id), s.frames, rate, length,
               s.fd ? "FD" : s.remote ? "RTR" : "", m != nullptr ? m->name : "");
  }
  return kExitOk;
}

}  // namespace

void register_can_commands(CLI::App& app, int& status) {
  auto decode = std::make_shared<DecodeOptions>();
  CLI::App* d = app.add_subcommand("can-decode", "Decode a candump -L log's signals with a DBC file, as CSV");
  d->add_option("log", decode->log, "candump -L log file")->required();
  d->add_option("--dbc", decode->dbc, "DBC file describing the messages")->required();
  d->add_option("--signals", decode->signals, "Signals to decode (NAME or MESSAGE.NAME), comma separated; default all")
      ->delimiter(',');
  d->add_option("--csv", decode->csv, "Write the CSV here instead of standard output");
  d->add_option("--bus", decode->bus, "Only frames from this interface (e.g. can0)");
  d->add_flag("--physical", decode->physical, "Keep the DBC's units instead of converting to SI");
  d->callback([decode, &status] { status = run_decode(*decode); });

  auto info_log = std::make_shared<std::string>();
  auto info_dbc = std::make_shared<std::string>();
  CLI::App* i = app.add_subcommand("can-info", "Summarise a candump -L log: ids, rates, lengths, buses and errors");
  i->add_option("log", *info_log, "candump -L log file")->required();
  i->add_option("--dbc", *info_dbc, "DBC file to name the ids and check their lengths");
  i->callback([info_log, info_dbc, &status] { status = run_info(*info_log, *info_dbc); });
}

}  // namespace adit::tools
