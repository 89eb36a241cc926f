#include "adit/drivers/lidar/ouster_digest.hpp"

#include <openssl/evp.h>

#include <array>
#include <memory>
#include <stdexcept>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/drivers/lidar/ouster_metadata.hpp"
#include "adit/drivers/lidar/ouster_packet.hpp"
#include "adit/drivers/pcap_reader.hpp"

namespace adit::drivers {
namespace {

// MD5 (RFC 1321) through OpenSSL's EVP interface.
class Md5 {
 public:
  Md5() : ctx_(EVP_MD_CTX_new(), &EVP_MD_CTX_free) {
    if (!ctx_ || EVP_DigestInit_ex(ctx_.get(), EVP_md5(), nullptr) != 1)
      throw std::runtime_error("OpenSSL cannot provide MD5");
  }
  void update(const std::vector<std::uint8_t>& bytes) { EVP_DigestUpdate(ctx_.get(), bytes.data(), bytes.size()); }
  std::string hex() {
    std::array<unsigned char, EVP_MAX_MD_SIZE> md{};
    unsigned int len = 0;
    EVP_DigestFinal_ex(ctx_.get(), md.data(), &len);
    std::string out;
    for (unsigned int i = 0; i < len; ++i) out += fmt::format("{:02x}", md[i]);
    return out;
  }

 private:
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx_;
};

void put(std::vector<std::uint8_t>& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}
void put_at(std::vector<std::uint8_t>& out, std::size_t index, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out[index * bytes + i] = static_cast<std::uint8_t>(value >> (8 * i));
}

enum class Kind : std::uint8_t { range, signal, reflectivity, near_ir, flags, raw32 };

struct PixelField {
  std::string_view name;
  int bytes;      // element size in the SDK
  Kind kind;
  int index;      // return (0/1), or word for raw32
};

std::uint64_t value_of(const PixelField& f, OusterProfile profile, const std::uint8_t* px) {
  if (f.kind == Kind::raw32) return ouster_le::u32(px + 4 * f.index);
  const OusterReturn r = read_return(profile, px, f.index);
  switch (f.kind) {
    case Kind::range: return r.range_mm;
    case Kind::signal: return r.signal;
    case Kind::reflectivity: return r.reflectivity;
    case Kind::near_ir: return r.near_ir;
    case Kind::flags: return r.flags;
    case Kind::raw32: break;
  }
  return 0;
}

// The SDK's packet fields per profile, in its ChanField order.
std::vector<PixelField> packet_fields(OusterProfile profile) {
  const PixelField range{"RANGE", 4, Kind::range, 0}, range2{"RANGE2", 4, Kind::range, 1};
  const PixelField signal{"SIGNAL", 2, Kind::signal, 0}, signal2{"SIGNAL2", 2, Kind::signal, 1};
  const PixelField refl{"REFLECTIVITY", 1, Kind::reflectivity, 0}, refl2{"REFLECTIVITY2", 1, Kind::reflectivity, 1};
  const PixelField nir{"NEAR_IR", 2, Kind::near_ir, 0};
  const PixelField flags{"FLAGS", 1, Kind::flags, 0}, flags2{"FLAGS2", 1, Kind::flags, 1};
  const auto word = [](int i) {
    static constexpr std::array<std::string_view, 4> names = {"RAW32_WORD1", "RAW32_WORD2", "RAW32_WORD3",
                                                              "RAW32_WORD4"};
    return PixelField{names[static_cast<std::size_t>(i)], 4, Kind::raw32, i};
  };
  switch (profile) {
    case OusterProfile::legacy: return {range, signal, refl, nir, flags};
    case OusterProfile::rng15_rfl8_nir8: return {range, refl, nir, flags, word(0)};
    case OusterProfile::rng19_rfl8_sig16_nir16: return {range, signal, refl, nir, flags, word(0), word(1), word(2)};
    case OusterProfile::rng19_rfl8_sig16_nir16_dual:
      return {range, range2, signal, signal2, refl, refl2, nir, flags, flags2, word(0), word(1), word(2), word(3)};
  }
  return {};
}

// The SDK's LidarScan fields per profile, in the order it creates them.
std::vector<PixelField> scan_fields(OusterProfile profile) {
  const PixelField range{"RANGE", 4, Kind::range, 0}, range2{"RANGE2", 4, Kind::range, 1};
  const PixelField signal{"SIGNAL", 2, Kind::signal, 0}, signal2{"SIGNAL2", 2, Kind::signal, 1};
  const PixelField refl{"REFLECTIVITY", 1, Kind::reflectivity, 0}, refl2{"REFLECTIVITY2", 1, Kind::reflectivity, 1};
  const PixelField nir{"NEAR_IR", 2, Kind::near_ir, 0};
  switch (profile) {
    case OusterProfile::legacy: return {range, signal, nir, refl};
    case OusterProfile::rng15_rfl8_nir8: return {range, refl, nir};
    case OusterProfile::rng19_rfl8_sig16_nir16: return {range, signal, refl, nir};
    case OusterProfile::rng19_rfl8_sig16_nir16_dual: return {range, range2, signal, signal2, refl, refl2, nir};
  }
  return {};
}

struct HeaderField {
  std::string_view name;
  int packet_bytes;
  int scan_bytes;
  std::uint64_t (*get)(const OusterColumnHeader&);
};

constexpr std::array<HeaderField, 5> kHeaderFields = {{
    {"TIMESTAMP", 8, 8, [](const OusterColumnHeader& h) -> std::uint64_t { return h.timestamp_ns; }},
    {"ENCODER_COUNT", 4, 8, [](const OusterColumnHeader& h) -> std::uint64_t { return h.encoder_count; }},
    {"MEASUREMENT_ID", 2, 2, [](const OusterColumnHeader& h) -> std::uint64_t { return h.measurement_id; }},
    {"STATUS", 4, 8, [](const OusterColumnHeader& h) -> std::uint64_t { return h.status; }},
    {"FRAME_ID", 2, 0, [](const OusterColumnHeader& h) -> std::uint64_t { return h.frame_id; }},
}};
// The scan's column fields, in the order the SDK's digest lists them.
constexpr std::array<std::size_t, 4> kScanHeaderOrder = {0, 3, 2, 1};

// One assembled frame: per-column headers and H x W field images, staggered.
class ScanImages {
 public:
  ScanImages(const OusterMetadata& m, std::vector<PixelField> fields)
      : width_(static_cast<std::size_t>(m.columns_per_frame)),
        height_(static_cast<std::size_t>(m.pixels_per_column)),
        fields_(std::move(fields)) {}

  bool empty() const { return columns_ == 0; }
  std::uint16_t frame_id() const { return frame_id_; }

  void start(std::uint16_t frame_id) {
    frame_id_ = frame_id;
    columns_ = 0;
    headers_.assign(kScanHeaderOrder.size(), {});
    for (std::size_t i = 0; i < kScanHeaderOrder.size(); ++i)
      headers_[i].assign(width_ * static_cast<std::size_t>(kHeaderFields[kScanHeaderOrder[i]].scan_bytes), 0);
    images_.assign(fields_.size(), {});
    for (std::size_t i = 0; i < fields_.size(); ++i)
      images_[i].assign(width_ * height_ * static_cast<std::size_t>(fields_[i].bytes), 0);
  }

  void add_column(const OusterPacketLayout& layout, const std::uint8_t* column) {
    const OusterColumnHeader h = read_column_header(layout, column);
    if (h.measurement_id >= width_) return;
    ++columns_;
    for (std::size_t i = 0; i < kScanHeaderOrder.size(); ++i) {
      const HeaderField& f = kHeaderFields[kScanHeaderOrder[i]];
      put_at(headers_[i], h.measurement_id, f.get(h), f.scan_bytes);
    }
    if (!h.valid) return;  // the SDK leaves an unmeasured column's pixels at zero
    for (std::size_t row = 0; row < height_; ++row) {
      const std::uint8_t* px = layout.pixel(column, static_cast<int>(row));
      for (std::size_t i = 0; i < fields_.size(); ++i)
        put_at(images_[i], row * width_ + h.measurement_id, value_of(fields_[i], layout.profile, px), fields_[i].bytes);
    }
  }

  nlohmann::ordered_json digest() const {
    nlohmann::ordered_json j;
    j["FRAME_ID"] = std::to_string(frame_id_);
    for (std::size_t i = 0; i < kScanHeaderOrder.size(); ++i) {
      Md5 md5;
      md5.update(headers_[i]);
      j[std::string(kHeaderFields[kScanHeaderOrder[i]].name)] = md5.hex();
    }
    for (std::size_t i = 0; i < fields_.size(); ++i) {
      Md5 md5;
      md5.update(images_[i]);
      j[std::string(fields_[i].name)] = md5.hex();
    }
    return j;
  }

 private:
  std::size_t width_;
  std::size_t height_;
  std::vector<PixelField> fields_;
  std::uint16_t frame_id_ = 0;
  std::size_t columns_ = 0;
  std::vector<std::vector<std::uint8_t>> headers_;
  std::vector<std::vector<std::uint8_t>> images_;
};

}  // namespace

std::string ouster_digest_json(const std::filesystem::path& pcap, const std::filesystem::path& metadata_file) {
  const OusterMetadata m = load_ouster_metadata(metadata_file);
  const OusterPacketLayout layout = OusterPacketLayout::of(m);
  const std::vector<PixelField> fields = packet_fields(m.lidar_profile);

  std::vector<Md5> header_md5(kHeaderFields.size());
  std::vector<Md5> field_md5(fields.size());
  ScanImages scan(m, scan_fields(m.lidar_profile));
  nlohmann::ordered_json scans = nlohmann::ordered_json::array();
  std::vector<std::uint8_t> buf;

  PcapReader reader(pcap);
  UdpDatagram d;
  while (reader.next(d)) {
    if (d.dst_port != m.udp_port_lidar || d.payload.size() != layout.packet_bytes) continue;
    const std::uint8_t* packet = d.payload.data();
    std::vector<OusterColumnHeader> headers(static_cast<std::size_t>(layout.columns_per_packet));
    for (int c = 0; c < layout.columns_per_packet; ++c)
      headers[static_cast<std::size_t>(c)] = read_column_header(layout, layout.column(packet, c));
    for (std::size_t f = 0; f < kHeaderFields.size(); ++f) {
      buf.clear();
      for (const auto& h : headers) put(buf, kHeaderFields[f].get(h), kHeaderFields[f].packet_bytes);
      header_md5[f].update(buf);
    }
    for (std::size_t f = 0; f < fields.size(); ++f) {
      buf.clear();
      for (int row = 0; row < layout.pixels_per_column; ++row)
        for (int c = 0; c < layout.columns_per_packet; ++c)
          put(buf, value_of(fields[f], layout.profile, layout.pixel(layout.column(packet, c), row)), fields[f].bytes);
      field_md5[f].update(buf);
    }
    // A scan is the run of packets of one frame id (the SDK's ScanBatcher).
    const std::uint16_t frame_id = read_packet_frame_id(layout, packet);
    if (scan.empty() || frame_id != scan.frame_id()) {
      if (!scan.empty()) scans.push_back(scan.digest());
      scan.start(frame_id);
    }
    for (int c = 0; c < layout.columns_per_packet; ++c) scan.add_column(layout, layout.column(packet, c));
  }
  if (!scan.empty()) scans.push_back(scan.digest());

  nlohmann::ordered_json packet_hash;
  for (std::size_t f = 0; f < kHeaderFields.size(); ++f)
    packet_hash[std::string(kHeaderFields[f].name)] = header_md5[f].hex();
  for (std::size_t f = 0; f < fields.size(); ++f) packet_hash[std::string(fields[f].name)] = field_md5[f].hex();
  nlohmann::ordered_json out;
  out["packet_hash"] = packet_hash;
  out["scans"] = scans;
  return out.dump(4) + "\n";
}

}  // namespace adit::drivers
