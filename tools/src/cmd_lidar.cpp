// adit pcap-info / decode / pcap-send: LiDAR captures on the bench.

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/common/main.hpp"
#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/ouster_digest.hpp"
#include "adit/drivers/lidar/registry.hpp"
#include "adit/drivers/lidar/scan_files.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "adit/drivers/udp.hpp"
#include "capture_sender.hpp"
#include "commands.hpp"

namespace adit::tools {
namespace {

using drivers::DetectedLidar;
using drivers::PcapReader;
using drivers::UdpDatagram;

struct Detected {
  DetectedLidar lidar;
  std::uint16_t port = 0;
  std::vector<std::uint8_t> first_packet;
};

// The first data packet any family recognises (optionally only on `port`).
Detected detect(const std::filesystem::path& file, std::optional<std::uint16_t> port) {
  PcapReader reader(file);
  UdpDatagram d;
  while (reader.next(d)) {
    if (port && d.dst_port != *port) continue;
    if (DetectedLidar found = drivers::detect_lidar(d.payload, d.dst_port); found.family != nullptr) {
      return {std::move(found), d.dst_port, {d.payload.begin(), d.payload.end()}};
    }
  }
  return {};
}

struct DecodeOptions {
  std::string file;
  std::string calibration;
  std::string model;
  std::string family;
  int port = 0;
  float cut_deg = 0.0F;
};

void add_decode_options(CLI::App* cmd, DecodeOptions& o) {
  cmd->add_option("FILE", o.file, "Capture file (classic libpcap)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--calibration", o.calibration, "Calibration or metadata file of the sensor (Velodyne YAML, ...)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--family", o.family, "Sensor family, when detection is not wanted (velodyne, ...)");
  cmd->add_option("--model", o.model, "Sensor model, when detection is not wanted (e.g. VLP-16)");
  cmd->add_option("--port", o.port, "Only data packets to this UDP port (default: the detected sensor's)")
      ->check(CLI::Range(1, 65535));
  cmd->add_option("--cut-deg", o.cut_deg, "Azimuth where scans are cut, degrees (default 0)")->check(CLI::Range(0.0, 360.0));
}

struct Decoding {
  std::unique_ptr<drivers::LidarDecoder> decoder;
  std::unique_ptr<drivers::ScanAssembler> assembler;
  std::string family;
  std::string model;
  std::uint16_t port = 0;
};

Decoding make_decoding(const DecodeOptions& o) {
  const std::optional<std::uint16_t> port =
      o.port > 0 ? std::optional<std::uint16_t>(static_cast<std::uint16_t>(o.port)) : std::nullopt;
  Detected found = detect(o.file, port);
  const drivers::LidarFamily* family = found.lidar.family;
  std::string model = found.lidar.model;
  if (!o.family.empty()) {
    family = drivers::find_lidar_family(o.family);
    if (family == nullptr) throw InputError("", "--family", "unknown family: " + o.family);
  }
  if (!o.model.empty()) model = o.model;
  if (family == nullptr || model.empty()) {
    throw InputError(o.file, "", "no known LiDAR data packets found (give --family and --model)");
  }
  Decoding out;
  out.decoder = family->make_decoder(model, o.calibration);
  out.family = std::string(family->name);
  out.model = model;
  out.port = port.value_or(found.port != 0 ? found.port : out.decoder->default_port());
  const std::int64_t period = family->packet_period_ns(model, found.first_packet);
  out.assembler =
      std::make_unique<drivers::ScanAssembler>(drivers::assembler_config_for(*out.decoder, period, o.cut_deg));
  return out;
}

void print_packet_counters(const drivers::PacketCounters& c) {
  fmt::print("packets: {} ok, {} auxiliary, {} foreign, {} truncated, {} malformed\n", c.count(drivers::PacketStatus::ok),
             c.count(drivers::PacketStatus::auxiliary), c.count(drivers::PacketStatus::foreign),
             c.count(drivers::PacketStatus::truncated), c.count(drivers::PacketStatus::malformed));
}

void print_assembly(const drivers::ScanAssemblerTotals& t) {
  fmt::print("scans: {} ({} complete); packets missing {}, duplicated {}, out of order {}; points dropped {}\n", t.scans,
             t.complete_scans, t.missing_packets, t.duplicate_packets, t.out_of_order_packets, t.dropped_points);
}

struct PortStats {
  std::uint64_t count = 0;
  std::int64_t first_ns = 0;
  std::int64_t last_ns = 0;
  std::vector<std::int64_t> intervals;
  std::map<std::size_t, std::uint64_t> sizes;
};

int pcap_info(const DecodeOptions& o) {
  std::map<std::uint16_t, PortStats> ports;
  PcapReader reader(o.file);
  UdpDatagram d;
  while (reader.next(d)) {
    PortStats& p = ports[d.dst_port];
    if (p.count > 0) p.intervals.push_back(d.capture_time_ns - p.last_ns);
    if (p.count++ == 0) p.first_ns = d.capture_time_ns;
    p.last_ns = d.capture_time_ns;
    ++p.sizes[d.payload.size()];
  }
  const drivers::PcapStats& s = reader.stats();
  fmt::print("file: {}\nrecords: {}; UDP datagrams: {} ({} reassembled from fragments); non-UDP: {}; damaged: {}; "
             "fragments dropped: {}\n",
             o.file, s.records, s.datagrams, s.reassembled, s.non_udp, s.damaged, s.fragments_dropped);
  for (auto& [port, p] : ports) {
    const double span_s = static_cast<double>(p.last_ns - p.first_ns) * 1e-9;
    std::string sizes;
    for (const auto& [size, n] : p.sizes) sizes += fmt::format("{}{}×{}", sizes.empty() ? "" : ", ", n, size);
    std::sort(p.intervals.begin(), p.intervals.end());
    const double median_ms = p.intervals.empty() ? 0.0 : p.intervals[p.intervals.size() / 2] * 1e-6;
    const double largest_ms = p.intervals.empty() ? 0.0 : p.intervals.back() * 1e-6;
    const auto gaps = std::count_if(p.intervals.begin(), p.intervals.end(),
                                    [&](std::int64_t i) { return i * 1e-6 > 3.0 * median_ms; });
    fmt::print("port {}: {} datagrams over {:.3f} s ({:.1f}/s), sizes {}; interval median {:.3f} ms, largest {:.3f} ms, "
               "{} gaps over 3× the median\n",
               port, p.count, span_s, span_s > 0 ? (p.count - 1) / span_s : 0.0, sizes, median_ms, largest_ms, gaps);
  }
  const Detected found = detect(o.file, o.port > 0 ? std::optional<std::uint16_t>(o.port) : std::nullopt);
  if (found.lidar.family == nullptr) {
    // Say what was seen, so that an unknown model or a firmware variant can be named.
    std::string seen;
    for (const auto& [port, p] : ports) {
      if (o.port > 0 && port != o.port) continue;
      std::string sizes;
      for (const auto& [size, n] : p.sizes) sizes += fmt::format("{}{} B", sizes.empty() ? "" : "/", size);
      seen += fmt::format("{}port {} ({})", seen.empty() ? "" : ", ", port, sizes);
    }
    fmt::print("sensor: none recognised; saw {}\nknown data packets: {}\n", seen.empty() ? "no UDP datagrams" : seen,
               drivers::known_lidar_packets());
    return kExitOk;
  }
  fmt::print("sensor: {} {} (data on port {})\n", found.lidar.family->name, found.lidar.model, found.port);
  if (o.calibration.empty() && found.lidar.family->name == "velodyne") {
    fmt::print("scans: give --calibration to decode them\n");
    return kExitOk;
  }
  Decoding decoding = make_decoding(o);
  std::vector<std::size_t> points;
  drivers::DecodeStream stream(*decoding.decoder, *decoding.assembler,
                               [&](drivers::LidarScan& scan) { points.push_back(scan.points.size()); });
  PcapReader again(o.file);
  while (again.next(d)) stream.push(d.payload, d.capture_time_ns);
  stream.finish();
  print_packet_counters(stream.counters());
  print_assembly(decoding.assembler->totals());
  if (!points.empty()) {
    std::sort(points.begin(), points.end());
    fmt::print("points per scan: min {}, median {}, max {}\n", points.front(), points[points.size() / 2], points.back());
  }
  if (const auto clock = stream.clock().estimate()) {
    fmt::print("clock: host − sensor {:.3f} ms, drift {:.1f} ppm\n", clock->offset_ns * 1e-6, clock->drift_ppm);
  }
  return kExitOk;
}

int decode(const DecodeOptions& o, const std::string& out_dir, const std::string& format) {
  Decoding decoding = make_decoding(o);
  std::filesystem::create_directories(out_dir);
  std::size_t written = 0;
  drivers::DecodeStream stream(*decoding.decoder, *decoding.assembler, [&](drivers::LidarScan& scan) {
    const auto path = std::filesystem::path(out_dir) / fmt::format("scan_{:06d}.{}", written++, format);
    if (format == "ply") {
      drivers::write_ply(path, scan);
    } else {
      drivers::write_pcd(path, scan);
    }
  });
  PcapReader reader(o.file);
  UdpDatagram d;
  // Every datagram goes to the decoder: it takes data and auxiliary packets and counts the rest as foreign.
  while (reader.next(d)) stream.push(d.payload, d.capture_time_ns);
  stream.finish();
  fmt::print("{} {}: wrote {} scans to {}\n", decoding.family, decoding.model, written, out_dir);
  print_packet_counters(stream.counters());
  print_assembly(decoding.assembler->totals());
  return kExitOk;
}

int pcap_send(const std::string& file, const std::string& to, double speed, int only_port) {
  const auto [host, port] = drivers::parse_host_port(to, "--to");
  const std::atomic<bool> never{false};
  const SendRoute route{only_port, port};
  const SendTotals totals = send_capture(file, host, std::span(&route, 1), speed, never);
  fmt::print("sent {} datagrams to {} ({} refused)\n", totals.sent, to, totals.refused);
  return totals.refused == 0 ? kExitOk : kExitFailure;
}

}  // namespace

void register_lidar_commands(CLI::App& app, int& status) {
  // Option storage lives in the callbacks that read it.
  auto info_options = std::make_shared<DecodeOptions>();
  CLI::App* info = app.add_subcommand("pcap-info", "Describe a LiDAR capture: sensor, packets per port, rate, gaps, scans");
  add_decode_options(info, *info_options);
  info->callback([&status, info_options] { status = pcap_info(*info_options); });

  struct DecodeCommand {
    DecodeOptions options;
    std::string out_dir;
    std::string format = "pcd";
    bool ouster_digest = false;
  };
  auto decode_command = std::make_shared<DecodeCommand>();
  CLI::App* dec = app.add_subcommand("decode", "Decode a LiDAR capture into one point-cloud file per scan");
  add_decode_options(dec, decode_command->options);
  dec->add_option("--out", decode_command->out_dir, "Directory for the scan files (created; required unless --ouster-digest)");
  dec->add_option("--format", decode_command->format, "pcd or ply (binary, every point field; default pcd)")
      ->check(CLI::IsMember({"pcd", "ply"}));
  dec->add_flag("--ouster-digest", decode_command->ouster_digest,
                "Ouster: print MD5 digests of every decoded field as JSON, in the layout of the Ouster SDK's "
                "*_digest.json files (needs --calibration METADATA.json)");
  dec->callback([&status, decode_command] {
    const DecodeCommand& c = *decode_command;
    if (c.ouster_digest) {
      if (c.options.calibration.empty())
        throw InputError(c.options.file, "--calibration", "--ouster-digest needs the sensor metadata JSON");
      fmt::print("{}\n", drivers::ouster_digest_json(c.options.file, c.options.calibration));
      status = kExitOk;
      return;
    }
    if (c.out_dir.empty()) throw InputError(c.options.file, "--out", "a directory for the scan files is required");
    status = decode(c.options, c.out_dir, c.format);
  });

  struct SendCommand {
    std::string file;
    std::string to;
    double speed = 1.0;
    int only_port = 0;
  };
  auto send_command = std::make_shared<SendCommand>();
  CLI::App* send = app.add_subcommand("pcap-send", "Send a capture's UDP payloads to HOST:PORT at X times the recorded rate");
  send->add_option("FILE", send_command->file, "Capture file (classic libpcap)")->required()->check(CLI::ExistingFile);
  send->add_option("--to", send_command->to, "Destination HOST:PORT")->required();
  send->add_option("--speed", send_command->speed, "Times the recorded rate; 0 sends as fast as possible (default 1)")
      ->check(CLI::Range(0.0, 1e6));
  send->add_option("--port", send_command->only_port, "Only datagrams that were sent to this UDP port")
      ->check(CLI::Range(1, 65535));
  send->callback([&status, send_command] {
    status = pcap_send(send_command->file, send_command->to, send_command->speed, send_command->only_port);
  });
}

}  // namespace adit::tools
