#include "adit/drivers/ipv4_reassembly.hpp"

#include <algorithm>
#include <cstring>

namespace adit::drivers {

Ipv4Reassembler::Ipv4Reassembler(std::size_t slots) : slots_(std::max<std::size_t>(slots, 1)) {
  for (Slot& slot : slots_) slot.data.resize(kMaxPayload);
}

Ipv4Reassembler::Slot& Ipv4Reassembler::slot_for(const Key& key) {
  Slot* free = nullptr;
  Slot* oldest = &slots_.front();
  for (Slot& slot : slots_) {
    if (slot.busy && slot.key == key) return slot;
    if (!slot.busy && free == nullptr) free = &slot;
    if (slot.busy && slot.age < oldest->age) oldest = &slot;
  }
  Slot& chosen = free != nullptr ? *free : *oldest;
  if (chosen.busy) release(chosen, true);
  chosen.busy = true;
  chosen.key = key;
  return chosen;
}

void Ipv4Reassembler::release(Slot& slot, bool dropped) {
  if (dropped) dropped_ += slot.fragments;
  slot.busy = false;
  slot.total = 0;
  slot.covered_blocks = 0;
  slot.fragments = 0;
  slot.blocks.fill(0);
}

Ipv4Reassembler::Result Ipv4Reassembler::add(const Key& key, std::size_t offset, bool more_fragments,
                                             std::span<const std::uint8_t> payload) {
  const std::size_t end = offset + payload.size();
  // Every fragment but the last carries a multiple of 8 bytes (RFC 791 §3.2).
  if (payload.empty() || end > kMaxPayload || (more_fragments && payload.size() % 8 != 0)) {
    return {Status::invalid, {}};
  }
  Slot& slot = slot_for(key);
  slot.age = ++clock_;
  ++slot.fragments;
  if (!more_fragments) {
    if (slot.total != 0 && slot.total != end) {
      release(slot, true);
      return {Status::invalid, {}};
    }
    slot.total = end;
  }
  if (slot.total != 0 && end > slot.total) {
    release(slot, true);
    return {Status::invalid, {}};
  }
  std::memcpy(slot.data.data() + offset, payload.data(), payload.size());
  // Overlapping or repeated fragments simply overwrite: later data wins.
  for (std::size_t block = offset / 8; block < (end + 7) / 8; ++block) {
    std::uint64_t& word = slot.blocks[block / 64];
    const std::uint64_t bit = std::uint64_t{1} << (block % 64);
    if ((word & bit) == 0) {
      word |= bit;
      ++slot.covered_blocks;
    }
  }
  if (slot.total == 0 || slot.covered_blocks != (slot.total + 7) / 8) return {Status::pending, {}};
  const std::span<const std::uint8_t> datagram(slot.data.data(), slot.total);
  release(slot, false);
  return {Status::complete, datagram};
}

std::uint64_t Ipv4Reassembler::pending_fragments() const {
  std::uint64_t count = 0;
  for (const Slot& slot : slots_) count += slot.busy ? slot.fragments : 0;
  return count;
}

void Ipv4Reassembler::clear() {
  for (Slot& slot : slots_) {
    if (slot.busy) release(slot, true);
  }
}

}  // namespace adit::drivers
