// adit faults pcap | can | lcm: the faults a payload meets in the field, put
// into recordings and onto the network on a schedule, to try aditd against
// them (scripts/soak.sh, docs/SESSIONS.md "Faults"):
//   pcap  a LiDAR capture with its cable out (every packet of a window gone),
//         packets lost, repeated and held back behind the next one;
//   can   a candump -L log with the bus off (CAN_ERR_BUSOFF, nothing on the
//         bus, CAN_ERR_RESTARTED; linux/can/error.h) and frames of some ids
//         missing for a while (an IMU dropping out);
//   lcm   garbage (random bytes of random sizes) on a payload's LCM channels.
// A window is AT:FOR seconds from the recording's start, repeated every
// --every seconds when given. Seeded: the same seed, the same faults.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <lcm/lcm-cpp.hpp>

#include "adit/common/error.hpp"
#include "adit/drivers/can/candump.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "adit/drivers/pcap_writer.hpp"
#include "adit/protocol/channels.hpp"
#include "commands.hpp"

namespace adit::tools {
namespace {

// [at, at + length) seconds after the start, again every `every` s (0: once).
struct Window {
  double at = -1.0;
  double length = 0.0;
  bool contains(double t, double every) const {
    if (at < 0) return false;
    const double local = every > 0 ? t - every * std::floor(t / every) : t;
    return local >= at && local < at + length;
  }
};

Window parse_window(const std::string& text, const std::string& option) {
  Window w;
  if (text.empty()) return w;
  if (std::sscanf(text.c_str(), "%lf:%lf", &w.at, &w.length) != 2 || w.at < 0 || w.length <= 0)
    throw InputError("", option, "expected AT:FOR in seconds, e.g. 10:2, not '" + text + "'");
  return w;
}

struct PcapOptions {
  std::string in, out;
  double loss = 0.0, repeat = 0.0, late = 0.0, every = 0.0;
  std::string cut;
  std::uint32_t seed = 1;
};

void faulty_pcap(const PcapOptions& o) {
  if (o.loss + o.repeat + o.late > 1.0) throw InputError("", "--loss", "--loss + --repeat + --late exceed 1");
  const Window cut = parse_window(o.cut, "--cut");
  drivers::PcapReader reader(o.in);
  drivers::PcapWriter writer(o.out);
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  struct Held {
    std::int64_t time_ns;
    drivers::UdpEndpoints endpoints;
    std::vector<std::uint8_t> payload;
  };
  std::optional<Held> held;
  std::uint64_t packets = 0, cut_out = 0, lost = 0, repeated = 0, late = 0;
  std::int64_t t0 = -1;
  drivers::UdpDatagram d;
  while (reader.next(d)) {
    ++packets;
    if (t0 < 0) t0 = d.capture_time_ns;
    const double t = 1e-9 * static_cast<double>(d.capture_time_ns - t0);
    const drivers::UdpEndpoints e{d.src_ip, d.dst_ip, d.src_port, d.dst_port};
    if (cut.contains(t, o.every)) {
      ++cut_out;
      continue;
    }
    const double r = u(rng);
    if (r < o.loss) {
      ++lost;
      continue;
    }
    if (r < o.loss + o.late && !held) {  // sent after the next one
      held = Held{d.capture_time_ns, e, {d.payload.begin(), d.payload.end()}};
      ++late;
      continue;
    }
    writer.write_udp(d.capture_time_ns, e, d.payload);
    if (r < o.loss + o.late + o.repeat) {
      writer.write_udp(d.capture_time_ns, e, d.payload);
      ++repeated;
    }
    if (held) {
      writer.write_udp(held->time_ns, held->endpoints, held->payload);
      held.reset();
    }
  }
  if (held) writer.write_udp(held->time_ns, held->endpoints, held->payload);
  writer.flush();
  fmt::print("{}: {} packets; cable out {}, lost {}, repeated {}, late {}\n", o.out, packets, cut_out, lost, repeated,
             late);
}

struct CanOptions {
  std::string in, out;
  std::string bus_off, drop;
  std::vector<std::string> drop_ids;
  double every = 0.0;
};

void faulty_can(const CanOptions& o) {
  namespace can = drivers::can;
  const Window bus_off = parse_window(o.bus_off, "--bus-off");
  const Window drop = parse_window(o.drop, "--drop");
  std::vector<std::uint32_t> ids;
  for (const std::string& id : o.drop_ids) {
    std::size_t used = 0;
    unsigned long value = 0;
    try {
      value = std::stoul(id, &used, 0);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != id.size() || value > 0x1FFFFFFFUL)
      throw InputError("", "--drop-ids", "not a CAN id: '" + id + "'");
    ids.push_back(static_cast<std::uint32_t>(value));
  }
  can::CandumpReader reader(o.in);
  can::CandumpWriter writer(o.out);
  can::Frame f;
  std::int64_t t0 = -1;
  bool off = false;
  std::uint64_t frames = 0, silenced = 0, dropped = 0, episodes = 0;
  const auto controller = [&writer](const can::Frame& like, std::int64_t time_us, std::uint32_t error_class) {
    can::Frame e = like;
    e.time_us = time_us;
    e.error = true;
    e.extended = false;
    e.remote = false;
    e.fd = false;
    e.id = error_class;
    e.length = 8;
    e.data.fill(0);
    writer.write(e);
  };
  while (reader.next(f)) {
    ++frames;
    if (t0 < 0) t0 = f.time_us;
    const double t = 1e-6 * static_cast<double>(f.time_us - t0);
    const bool in_bus_off = bus_off.contains(t, o.every);
    if (in_bus_off != off) {
      controller(f, f.time_us - 1, in_bus_off ? 0x40U /* CAN_ERR_BUSOFF */ : 0x100U /* CAN_ERR_RESTARTED */);
      episodes += in_bus_off ? 1 : 0;
      off = in_bus_off;
    }
    if (off) {
      ++silenced;
      continue;
    }
    if (drop.contains(t, o.every) && std::find(ids.begin(), ids.end(), f.id) != ids.end()) {
      ++dropped;
      continue;
    }
    writer.write(f);
  }
  writer.flush();
  if (!reader.errors().empty())
    fmt::print(stderr, "adit faults can: {} malformed lines skipped, first: {}\n", reader.errors().size(),
               reader.describe(reader.errors().front()));
  fmt::print("{}: {} frames; bus off {} times ({} frames silenced), {} frames of the dropped ids\n", o.out, frames,
             episodes, silenced, dropped);
}

struct LcmOptions {
  std::string url, payload;
  double seconds = 3.0;
  std::uint32_t seed = 1;
};

void garbage_on_lcm(const LcmOptions& o) {
  lcm::LCM out(o.url);
  if (!out.good()) throw InputError(o.url, "--lcm-url", "LCM could not start");
  using protocol::Channel;
  const std::string channels[] = {protocol::channel_name(o.payload, Channel::command),
                                  protocol::channel_name(o.payload, Channel::tile_request),
                                  protocol::channel_name(o.payload, Channel::status), "ADIT/GARBAGE"};
  std::mt19937 rng(o.seed);
  std::vector<std::uint8_t> bytes(4096);
  std::uint64_t sent = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.seconds);
  while (std::chrono::steady_clock::now() < end) {
    const std::size_t n = 1 + rng() % bytes.size();
    for (std::size_t i = 0; i < n; ++i) bytes[i] = static_cast<std::uint8_t>(rng());
    out.publish(channels[sent % 4], bytes.data(), static_cast<unsigned>(n));
    ++sent;
  }
  fmt::print("{} garbage messages in {:.1f} s on {}'s channels\n", sent, o.seconds, o.payload);
}

}  // namespace

void register_faults_commands(CLI::App& app, int& status) {
  CLI::App* faults = app.add_subcommand("faults", "Put field faults into recordings and onto LCM, to try aditd against them");
  faults->require_subcommand(1);

  auto p = std::make_shared<PcapOptions>();
  CLI::App* pcap = faults->add_subcommand("pcap", "A LiDAR capture with its cable out, packets lost, repeated and late");
  pcap->add_option("IN", p->in, "Capture to read")->required()->check(CLI::ExistingFile);
  pcap->add_option("OUT", p->out, "Capture to write")->required();
  pcap->add_option("--cut", p->cut, "AT:FOR: the cable out (no packets) for FOR s from AT s");
  pcap->add_option("--loss", p->loss, "Fraction of packets lost")->check(CLI::Range(0.0, 1.0));
  pcap->add_option("--repeat", p->repeat, "Fraction of packets sent twice")->check(CLI::Range(0.0, 1.0));
  pcap->add_option("--late", p->late, "Fraction of packets sent after the next one")->check(CLI::Range(0.0, 1.0));
  pcap->add_option("--every", p->every, "Repeat the --cut window every S seconds (0: once)")->check(CLI::NonNegativeNumber);
  pcap->add_option("--seed", p->seed, "Random seed");
  pcap->callback([p, &status] {
    faulty_pcap(*p);
    status = kExitOk;
  });

  auto c = std::make_shared<CanOptions>();
  CLI::App* can = faults->add_subcommand("can", "A candump -L log with the bus off and some ids silent for a while");
  can->add_option("IN", c->in, "Log to read (candump -L)")->required()->check(CLI::ExistingFile);
  can->add_option("OUT", c->out, "Log to write")->required();
  can->add_option("--bus-off", c->bus_off, "AT:FOR: bus-off (error frames at both ends, nothing between)");
  can->add_option("--drop", c->drop, "AT:FOR: frames of --drop-ids missing (a sensor dropping out)");
  can->add_option("--drop-ids", c->drop_ids, "CAN ids to drop in the --drop window (e.g. 0x190)")->delimiter(',');
  can->add_option("--every", c->every, "Repeat the windows every S seconds (0: once)")->check(CLI::NonNegativeNumber);
  can->callback([c, &status] {
    faulty_can(*c);
    status = kExitOk;
  });

  auto l = std::make_shared<LcmOptions>();
  CLI::App* lcm = faults->add_subcommand("lcm", "Random bytes on a payload's LCM channels, as fast as one thread sends");
  lcm->add_option("--payload", l->payload, "Payload id whose channels get the garbage")->required();
  lcm->add_option("--lcm-url", l->url, "LCM URL")->required();
  lcm->add_option("--seconds", l->seconds, "How long")->check(CLI::PositiveNumber);
  lcm->add_option("--seed", l->seed, "Random seed");
  lcm->callback([l, &status] {
    garbage_on_lcm(*l);
    status = kExitOk;
  });
}

}  // namespace adit::tools
