// The LiDAR source stage. In: UDP datagrams, a pcap or a scan directory.
// Out: whole scans (sensor frame) to the odometry stage; raw pcap recording.
// Threads receiver and assembly; no allocation, lock or log per packet; a
// replay waits for room, live drops the oldest (counted). (lidar_source.hpp)
#include "adit/daemon/lidar_source.hpp"

#include <algorithm>
#include <cstring>
#include <memory>
#include <span>
#include <vector>

#include <fmt/format.h>

#include "adit/common/clock.hpp"
#include "adit/common/error.hpp"
#include "adit/common/log.hpp"
#include "adit/daemon/livox_imu.hpp"
#include "adit/daemon/ouster_imu.hpp"
#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/livox.hpp"
#include "adit/drivers/lidar/ouster_metadata.hpp"
#include "adit/drivers/lidar/registry.hpp"
#include "adit/drivers/lidar/scan_directory.hpp"
#include "adit/drivers/pcap_replay.hpp"
#include "adit/drivers/pcap_writer.hpp"
#include "adit/drivers/udp.hpp"

namespace adit::daemon {
namespace {

constexpr std::size_t kPacketSlots = 512;  // ~0.4 s of the busiest sensor (Ouster, 1280 packets/s)

struct Packet {
  std::int64_t host_time_ns = 0;      // capture or kernel time (the sensor clock's reference)
  std::uint32_t src_ip = 0;           // for the raw recording
  std::uint16_t src_port = 0;
  std::int64_t received_mono_ns = 0;  // when the receiver handed it on (latency)
  std::uint32_t size = 0;
  bool imu = false;                   // from the LiDAR's IMU port (imu.source ouster, livox)
  std::vector<std::uint8_t> data;     // packet_bytes_for(decoder), sized once
};

// The configured model's decoder (none for a directory of scans). Throws adit::InputError.
std::unique_ptr<drivers::LidarDecoder> decoder_of(const config::Config& c) {
  if (c.lidar.source == config::LidarSource::scan_dir) return nullptr;
  const drivers::LidarFamily* family = drivers::lidar_family_of_model(c.lidar.model);
  if (family == nullptr) throw InputError("", "lidar.model", "no decoder for " + c.lidar.model);
  try {
    return family->make_decoder(c.lidar.model, c.lidar.calibration);
  } catch (const InputError& e) {
    // The family speaks of its own inputs; name the configuration key.
    throw InputError(e.where().empty() ? c.lidar.calibration : e.where(), "lidar.calibration", e.reason());
  }
}

// Each pooled packet holds the longest datagram the configured decoder reads
// and one byte more, so that a longer datagram still reaches it too long (and
// is counted as it was) rather than cut to a valid size. A VLP-16's pool is
// then 0.6 MB, not the 33.5 MB of 64 kB a packet (docs/decisions/032-aditd-memory.md).
std::size_t packet_bytes_for(const drivers::LidarDecoder* decoder) {
  constexpr std::size_t kMaxDatagram = 65'536;
  return decoder != nullptr ? std::min(decoder->max_packet_bytes() + 1, kMaxDatagram) : 0;
}

}  // namespace

struct LidarSource::Impl {
  Impl(const config::Config& c, double speed, Overflow overflow, PipelineStats& s, const std::atomic<bool>& stop_flag,
       const std::atomic<bool>& end_flag, HostClock clock)
      : host_clock(clock),
        stats(s),
        stop(stop_flag),
        end(end_flag),
        receiver("receiver", c.threads.receiver, stop_flag),
        assembly("assembly", c.threads.receiver, stop_flag) {
    record_budget_bytes = static_cast<std::uint64_t>(c.session.record_budget_mb * 1e6);
    record_part_bytes = static_cast<std::uint64_t>(c.session.record_part_mb * 1e6);
    if (c.lidar.source == config::LidarSource::scan_dir) {
      scan_directory.emplace(c.lidar.scan_dir);
      packets.emplace(kPacketSlots, overflow, [] { return Packet{}; });  // no packets: scans come whole
      return;
    }
    if (c.lidar.source == config::LidarSource::pcap) pcap.emplace(c.lidar.pcap, speed);  // its name first
    decoder = decoder_of(c);
    packets.emplace(kPacketSlots, overflow, [bytes = packet_bytes_for(decoder.get())] {
      Packet p;
      p.data.resize(bytes);
      return p;
    });
    data_port = c.lidar.port != 0 ? static_cast<std::uint16_t>(c.lidar.port) : decoder->default_port();
    if (c.imu.enabled) make_imu(c);
    if (c.lidar.source == config::LidarSource::udp) {
      drivers::UdpReceiverConfig udp_config;
      udp_config.bind_address = c.lidar.address;
      udp_config.port = data_port;
      udp_config.interface = c.lidar.interface;
      udp_config.multicast_group = c.lidar.multicast_group;
      udp_config.receive_buffer_bytes = c.lidar.receive_buffer_bytes;
      udp.emplace(udp_config);
      if (imu_port != 0) {
        // The IMU's packets (Ouster 100 Hz, 48 bytes; Mid-360 200 Hz, 60 bytes) on their own port, read by the
        // same receiver thread into the same packet pool: the assembly thread
        // then sees both in arrival order and stamps the IMU with the LiDAR
        // stream's clock estimate without sharing it across threads (the
        // pool is single-producer, so a second thread could not feed it).
        udp_config.port = imu_port;
        udp_config.receive_buffer_bytes = 1 << 20;
        imu_udp.emplace(udp_config);
      }
    }
    // The packet period is learnt from the first data packet by the family
    // (learn_packet_period); until then, and for families without one, loss
    // is counted by sequence only.
    model = c.lidar.model;
    lidar_family = drivers::lidar_family_of_model(c.lidar.model);  // decoder_of found it
    assembler.emplace(drivers::assembler_config_for(*decoder, 0, static_cast<float>(c.lidar.scan_cut_azimuth_deg)));
    stream.emplace(*decoder, *assembler, [this](drivers::LidarScan& scan) { hand_on(scan); });
  }

  // The LiDAR's own IMU (imu.source ouster or livox) and where its packets
  // come: their own port (lidar.imu_port, else the Ouster's metadata says
  // which, the Mid-360's is 56401) or, for a Livox, among the points as packets the
  // decoder reports `auxiliary` (the Avia's SDK1 IMU packets). Throws
  // adit::InputError naming the file or key.
  void make_imu(const config::Config& c) {
    const bool replay = c.lidar.source == config::LidarSource::pcap;
    if (c.imu.source == config::ImuSource::ouster) {
      auto ouster = std::make_unique<OusterImu>(c, drivers::load_ouster_metadata(c.lidar.calibration), replay);
      imu_port = lidar_imu_port(c);
      if (imu_port == data_port)
        throw InputError(c.lidar.imu_port != 0 ? std::string() : c.lidar.calibration,
                         c.lidar.imu_port != 0 ? "lidar.imu_port" : "udp_port_imu",
                         fmt::format("{} is the LiDAR's port too (lidar.port)", imu_port));
      imu = std::move(ouster);
    } else if (c.imu.source == config::ImuSource::livox) {
      const std::optional<drivers::LivoxModel> livox = drivers::livox_model_from_name(c.lidar.model);
      if (!livox) throw InputError("", "imu.source", "livox needs a Livox LiDAR, not " + c.lidar.model);
      imu = std::make_unique<LivoxImu>(c, livox_imu_mounting(*livox, c.lidar.extrinsics), replay);
      const std::uint16_t port = lidar_imu_port(c);
      imu_port = port != data_port ? port : 0;  // 0: on the data port
      imu_among_points = true;
    }
  }

  bool reading() const { return !stop.load(std::memory_order_relaxed) && !end.load(std::memory_order_relaxed); }

  // Assembly thread (receiver thread for a scan directory): a finished scan
  // goes to odometry, swapped, not copied.
  void hand_on(drivers::LidarScan& scan) {
    stats.scans.fetch_add(1, std::memory_order_relaxed);
    if (imu) imu->lidar_reached(1e-9 * static_cast<double>(scan.start_time_ns));
    if (stream) {
      if (const auto clock = stream->clock().estimate())
        stats.clock_offset_ns.store(clock->offset_ns, std::memory_order_relaxed);
    }
    if (!scan.stats.complete) stats.incomplete_scans.fetch_add(1, std::memory_order_relaxed);
    if (assembler) {
      const drivers::ScanAssemblerTotals& t = assembler->totals();
      stats.missing_packets.store(t.missing_packets, std::memory_order_relaxed);
      stats.duplicate_packets.store(t.duplicate_packets, std::memory_order_relaxed);
      stats.late_packets.store(t.out_of_order_packets, std::memory_order_relaxed);
      stats.resyncs.store(t.resyncs, std::memory_order_relaxed);
    }
    ScanSlot* slot = scans->acquire_or_wait([this] { return assembly.idle(); });
    if (slot == nullptr) return;
    std::swap(slot->scan, scan);
    slot->last_packet_mono_ns = current_packet_mono_ns;
    scans->publish(slot);
  }

  // Receiver thread: one datagram into the packet pool (and the recording).
  void push(std::span<const std::uint8_t> payload, std::int64_t time_ns, std::uint32_t src_ip, std::uint16_t src_port,
            bool from_imu = false) {
    Packet* packet = packets->acquire_or_wait([this] { return receiver.idle(); });  // replay: wait for assembly
    if (packet == nullptr) return;
    packet->imu = from_imu;
    packet->host_time_ns = time_ns;
    if (!from_imu && time_ns > 0) {  // a silence by the stamps: the same in a replay as it was live
      if (const std::int64_t gap = time_ns - last_data_time_ns; last_data_time_ns > 0 && gap > kSilence_ns) {
        stats.silences.fetch_add(1, std::memory_order_relaxed);
        if (gap > stats.longest_silence_ns.load(std::memory_order_relaxed))
          stats.longest_silence_ns.store(gap, std::memory_order_relaxed);
      }
      last_data_time_ns = time_ns;
    }
    packet->src_ip = src_ip;
    packet->src_port = src_port;
    packet->size = static_cast<std::uint32_t>(std::min(payload.size(), packet->data.size()));
    std::memcpy(packet->data.data(), payload.data(), packet->size);
    packet->received_mono_ns = monotonic_ns();
    stats.last_packet_realtime_ns.store(realtime_ns(), std::memory_order_relaxed);
    stats.last_packet_mono_ns.store(packet->received_mono_ns, std::memory_order_relaxed);
    if (recorder && stats.recording_stopped.load(std::memory_order_relaxed) == 0) {
      // Buffered file output on the receiver: a copy and no allocation per packet.
      const drivers::UdpEndpoints endpoints{src_ip, 0xFFFFFFFF, src_port, from_imu ? imu_port : data_port};
      const std::uint64_t next = payload.size() + kRecordOverhead;
      if (record_budget_bytes > 0 && earlier_parts_bytes + recorder->bytes() + next > record_budget_bytes) {
        stop_recording(RecordingStop::budget);
      } else if (record_part_bytes > 0 && recorder->bytes() + next > record_part_bytes && !next_record_part()) {
        stop_recording(RecordingStop::write_failed);
      } else if (recorder->write_udp(time_ns > 0 ? time_ns : realtime_ns(), endpoints, payload)) {
        stats.recorded_datagrams.fetch_add(1, std::memory_order_relaxed);
        stats.recorded_bytes.store(earlier_parts_bytes + recorder->bytes(), std::memory_order_relaxed);
      }
      if (recorder->failed()) stop_recording(RecordingStop::write_failed);
    }
    packets->publish(packet);
  }

  // Receiver thread: the recording goes on in its next part (lidar.1.pcap,
  // ...: drivers/pcap_replay.hpp reads them as one), once per
  // session.record_part_mb; false (logged) when the part cannot be opened.
  bool next_record_part() {
    try {
      recorder->flush();
      earlier_parts_bytes += recorder->bytes();
      recorder.emplace(drivers::pcap_part(record_file, ++record_part));
      return true;
    } catch (const std::exception& e) {
      log::error("LiDAR recording, part {}: {}", record_part, e.what());
      return false;
    }
  }

  // Receiver thread: a step of the host's wall clock (NTP, PTP) is counted and
  // shown; live stamps do not see it (host_clock), replayed ones are the capture's.
  void watch_the_clock() {
    if (const std::optional<std::int64_t> step = step_watch.look()) {
      stats.clock_steps.fetch_add(1, std::memory_order_relaxed);
      stats.last_clock_step_ns.store(*step, std::memory_order_relaxed);
    }
  }

  // The first reason wins; the status names it, the mapping goes on.
  void stop_recording(RecordingStop why) {
    int recording = 0;
    stats.recording_stopped.compare_exchange_strong(recording, static_cast<int>(why), std::memory_order_relaxed);
  }

  void receiver_loop() {
    if (scan_directory) return scan_directory_loop();
    if (pcap) {
      drivers::UdpDatagram d;
      while (reading() && pcap->next(d)) {
        receiver.beat.beat();
        watch_the_clock();
        stats.datagrams.fetch_add(1, std::memory_order_relaxed);
        if (imu_port != 0 && d.dst_port == imu_port) {
          push(d.payload, d.capture_time_ns, d.src_ip, d.src_port, true);
          continue;
        }
        if (d.dst_port != data_port) {
          stats.foreign_datagrams.fetch_add(1, std::memory_order_relaxed);
          continue;
        }
        push(d.payload, d.capture_time_ns, d.src_ip, d.src_port);
      }
    } else {
      // A pipeline built ahead of its session (Sessions keeps one ready) finds
      // old packets in the socket's buffer: they belong to no session.
      for (auto batch = udp->receive(0); !batch.empty(); batch = udp->receive(0))
        stats.stale_datagrams.fetch_add(batch.size(), std::memory_order_relaxed);
      if (imu_udp)
        for (auto batch = imu_udp->receive(0); !batch.empty(); batch = imu_udp->receive(0))
          stats.stale_datagrams.fetch_add(batch.size(), std::memory_order_relaxed);
      // With the IMU's socket beside it, the LiDAR's waits at most 5 ms, so
      // the IMU is read within 5 ms even when the LiDAR falls silent.
      const int wait_ms = imu_udp ? 5 : 100;
      // Live stamps go on the session's step-free timeline; a step of the
      // wall clock is counted (and shown) instead of reaching the odometry.
      const auto host_time = [this](std::int64_t kernel_ns) {
        return kernel_ns > 0 ? host_clock.from_recent_realtime(kernel_ns) : host_clock.now_ns();
      };
      // Drops before the session (while the pipeline waited) are not its own.
      const auto kernel_drops = [this] {
        return udp->stats().kernel_drops + (imu_udp ? imu_udp->stats().kernel_drops : 0);
      };
      const std::uint64_t drops_before = kernel_drops();
      while (reading()) {
        receiver.beat.beat();
        watch_the_clock();
        for (const drivers::ReceivedDatagram& d : udp->receive(wait_ms)) {
          stats.datagrams.fetch_add(1, std::memory_order_relaxed);
          push(d.payload, host_time(d.kernel_time_ns), d.src_ip, d.src_port);
        }
        if (imu_udp)
          for (const drivers::ReceivedDatagram& d : imu_udp->receive(0)) {
            stats.datagrams.fetch_add(1, std::memory_order_relaxed);
            push(d.payload, host_time(d.kernel_time_ns), d.src_ip, d.src_port, true);
          }
        stats.socket_drops.store(kernel_drops() - drops_before, std::memory_order_relaxed);
      }
    }
    if (recorder) {
      try {
        recorder->flush();
      } catch (const InputError& e) {
        stop_recording(RecordingStop::write_failed);
        log::error("{}: {}", e.where(), e.reason());
      }
    }
    packets->close();
  }

  void scan_directory_loop() {
    drivers::LidarScan scan;
    scan.points.reserve(scan_dir_points);
    while (reading() && scan_directory->next(scan)) {
      receiver.beat.beat();
      current_packet_mono_ns = monotonic_ns();
      hand_on(scan);
    }
    scans->close();
  }

  // Once, from the first data packet (its return mode sets the period).
  void learn_packet_period(std::span<const std::uint8_t> payload) {
    period_learnt = true;
    if (const std::int64_t period = lidar_family->packet_period_ns(model, payload); period > 0)
      assembler->set_packet_period_ns(period);
  }

  void assembly_loop() {
    if (scan_directory) return;
    // A stop drops what is queued; an ended source is drained.
    while (!stop.load(std::memory_order_relaxed)) {
      Packet* packet = packets->take_or_wait([this] { return assembly.idle(); });
      if (packet == nullptr) break;
      assembly.beat.beat();
      const std::span<const std::uint8_t> payload(packet->data.data(), packet->size);
      if (packet->imu) {
        imu->push(payload, packet->host_time_ns, packet->received_mono_ns, stream->clock());
      } else {
        current_packet_mono_ns = packet->received_mono_ns;
        if (!period_learnt) learn_packet_period(payload);
        const drivers::PacketStatus status = stream->push(payload, packet->host_time_ns);
        if (imu_among_points && status == drivers::PacketStatus::auxiliary)
          imu->push(payload, packet->host_time_ns, packet->received_mono_ns, stream->clock());
      }
      packets->release(packet);
    }
    if (!stop.load()) stream->finish();
    if (imu) imu->close();
    stats.bad_packets.store(stream->bad_packets());
    stats.dropped_packets.store(packets->dropped());
    scans->close();
  }

  const HostClock host_clock;  // live stamps (udp)
  static constexpr std::int64_t kSilence_ns = 1'000'000'000;
  std::int64_t last_data_time_ns = 0;  // receiver thread
  ClockStepWatch step_watch;   // receiver thread
  PipelineStats& stats;
  const std::atomic<bool>& stop;
  const std::atomic<bool>& end;
  std::size_t scan_dir_points = 0;
  std::unique_ptr<drivers::LidarDecoder> decoder;
  std::uint16_t data_port = 0;
  std::optional<drivers::PacedPcapReader> pcap;
  std::optional<drivers::UdpReceiver> udp;
  std::optional<drivers::ScanDirectorySource> scan_directory;
  std::optional<drivers::ScanAssembler> assembler;
  std::optional<drivers::DecodeStream> stream;
  std::optional<drivers::PcapWriter> recorder;
  const drivers::LidarFamily* lidar_family = nullptr;
  std::string model;
  bool period_learnt = false;  // assembly thread
  std::uint64_t record_budget_bytes = 0;  // 0: none
  std::uint64_t record_part_bytes = 0;    // 0: one file
  std::filesystem::path record_file;      // the first part
  int record_part = 0;
  std::uint64_t earlier_parts_bytes = 0;
  static constexpr std::size_t kRecordOverhead = 128;  // pcap, Ethernet, IP and UDP headers of one datagram
  std::unique_ptr<PacketImu> imu;         // imu.source ouster or livox (make_imu)
  std::uint16_t imu_port = 0;             // 0: no port of its own
  bool imu_among_points = false;          // a Livox: the data port's auxiliary packets are IMU packets
  std::optional<drivers::UdpReceiver> imu_udp;
  std::optional<Handoff<Packet>> packets;  // sized by the decoder, so built after it
  Handoff<ScanSlot>* scans = nullptr;      // the source's output, set before the threads start
  std::int64_t current_packet_mono_ns = 0;  // assembly thread only
  StageThread receiver;
  StageThread assembly;
};

namespace {
Overflow overflow_of(const config::Config& c) {
  return c.lidar.source == config::LidarSource::udp ? Overflow::drop_oldest : Overflow::wait;
}
}  // namespace

LidarSource::LidarSource(const config::Config& config, double replay_speed, std::size_t scan_dir_points,
                         PipelineStats& stats, const std::atomic<bool>& stop, HostClock clock)
    : impl_(std::make_unique<Impl>(config, replay_speed >= 0.0 ? replay_speed : config.lidar.replay_speed,
                                   overflow_of(config), stats, stop, end_, clock)),
      overflow_(overflow_of(config)),
      max_points_(impl_->assembler ? impl_->assembler->config().max_points_per_scan : scan_dir_points),
      scans_(kScanSlots, overflow_, [points = max_points_] {
        ScanSlot slot;
        slot.scan.points.reserve(points);
        return slot;
      }) {
  impl_->scan_dir_points = scan_dir_points;
  impl_->scans = &scans_;
}

LidarSource::~LidarSource() { join(); }

void LidarSource::record_to(const std::filesystem::path& file) {
  if (file.empty()) return;
  if (!impl_->udp && !impl_->pcap)
    throw InputError(file.string(), "session.record_lidar", "only packet sources can be recorded");
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  impl_->recorder.emplace(file);
  impl_->record_file = file;
}

void LidarSource::start() {
  impl_->assembly.start([this] { impl_->assembly_loop(); });
  impl_->receiver.start([this] { impl_->receiver_loop(); });
}

void LidarSource::join() {
  impl_->receiver.join();
  impl_->assembly.join();
}

std::vector<StageThread*> LidarSource::threads() { return {&impl_->receiver, &impl_->assembly}; }
std::size_t LidarSource::packets_waiting() const { return impl_->packets->depth(); }
std::size_t LidarSource::packet_capacity() const { return impl_->packets->capacity(); }
std::size_t LidarSource::packet_bytes() const { return packet_bytes_for(impl_->decoder.get()); }
PacketImu* LidarSource::imu() { return impl_->imu.get(); }

std::uint16_t lidar_imu_port(const config::Config& c) {
  if (c.lidar.imu_port != 0) return static_cast<std::uint16_t>(c.lidar.imu_port);
  if (!c.imu.enabled) return 0;
  if (c.imu.source == config::ImuSource::ouster) return drivers::load_ouster_metadata(c.lidar.calibration).udp_port_imu;
  if (c.imu.source == config::ImuSource::livox)
    if (const std::optional<drivers::LivoxModel> livox = drivers::livox_model_from_name(c.lidar.model))
      return drivers::livox_imu_port(*livox);
  return 0;
}

}  // namespace adit::daemon
