#pragma once
// MD5 digests of every field of an Ouster capture, in the JSON layout of the
// Ouster SDK's digest files (the `*_digest.json` beside our test captures): a
// bit-exact check of a decoder against the sensor maker's own.
//
//   packet_hash: per field, one MD5 over the field extracted packet by packet
//     (per packet a rows x columns_per_packet array, row-major, in the SDK's
//     packet field type: TIMESTAMP u64, ENCODER_COUNT u32, MEASUREMENT_ID u16,
//     STATUS u32, FRAME_ID u16 per column, RANGE u32, SIGNAL u16,
//     REFLECTIVITY u8, NEAR_IR u16, FLAGS u8, RAW32_WORDn u32);
//   scans[]: per scan (the packets of one frame id), FRAME_ID as a decimal
//     string and one MD5 per field of the H x W image in staggered column
//     order, row-major, in the SDK's scan field type (TIMESTAMP, STATUS and
//     ENCODER_COUNT u64 and MEASUREMENT_ID u16 per column; RANGE u32, SIGNAL
//     u16, REFLECTIVITY u8, NEAR_IR u16).
// Fields and their order follow the SDK's per-profile field tables; see
// docs/LIDAR-OUSTER.md.

#include <filesystem>
#include <string>

namespace adit::drivers {

// Reads the capture's lidar packets (the metadata's lidar port and packet
// size) and returns the digest JSON, indented by 4 like the SDK's files.
// Throws adit::InputError for unreadable or malformed files.
std::string ouster_digest_json(const std::filesystem::path& pcap, const std::filesystem::path& metadata);

}  // namespace adit::drivers
