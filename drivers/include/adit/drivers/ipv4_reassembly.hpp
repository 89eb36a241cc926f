#pragma once
// IPv4 fragment reassembly (RFC 791 §3.2, with RFC 815's hole tracking done
// as a bitmap of 8-byte fragment blocks). A fixed number of slots, each with a
// preallocated 64 KiB buffer, so a capture of fragmented Ouster packets is
// rebuilt without allocating per packet. When every slot is busy the oldest
// unfinished datagram is dropped (and its fragments counted).

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace adit::drivers {

class Ipv4Reassembler {
 public:
  struct Key {
    std::uint32_t src = 0;
    std::uint32_t dst = 0;
    std::uint16_t id = 0;
    std::uint8_t protocol = 0;
    bool operator==(const Key&) const = default;
  };
  enum class Status : std::uint8_t { pending, complete, invalid };
  struct Result {
    Status status = Status::pending;
    std::span<const std::uint8_t> datagram;  // the IP payload when complete; valid until the next add()
  };

  explicit Ipv4Reassembler(std::size_t slots = 8);

  // One fragment: `offset` in bytes into the IP payload, `payload` its bytes.
  Result add(const Key& key, std::size_t offset, bool more_fragments, std::span<const std::uint8_t> payload);

  // Fragments held by unfinished datagrams.
  std::uint64_t pending_fragments() const;
  // Fragments of datagrams given up (evicted, inconsistent, or cleared).
  std::uint64_t dropped_fragments() const { return dropped_; }
  // Gives up every unfinished datagram (end of a capture).
  void clear();

  static constexpr std::size_t kMaxPayload = 65535 - 20;

 private:
  static constexpr std::size_t kBlocks = (kMaxPayload + 7) / 8;
  struct Slot {
    bool busy = false;
    Key key;
    std::uint64_t age = 0;
    std::size_t total = 0;  // payload length, known once the last fragment arrived
    std::size_t covered_blocks = 0;
    std::uint32_t fragments = 0;
    std::vector<std::uint8_t> data;
    std::array<std::uint64_t, (kBlocks + 63) / 64> blocks{};
  };
  Slot& slot_for(const Key& key);
  void release(Slot& slot, bool dropped);

  std::vector<Slot> slots_;
  std::uint64_t clock_ = 0;
  std::uint64_t dropped_ = 0;
};

}  // namespace adit::drivers
