// PcapReader on arbitrary files: it either refuses the file with
// adit::InputError or reads it to the end, counting what it skips.
// Seeds: real captures (fuzz_pcap_reader.seeds).
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "adit/common/error.hpp"
#include "adit/drivers/pcap_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // libpcap reads files: hand it an in-memory one.
  const int fd = memfd_create("fuzz.pcap", 0);
  if (fd < 0) return 0;
  if (write(fd, data, size) != static_cast<ssize_t>(size)) {
    close(fd);
    return 0;
  }
  const std::string path = "/proc/self/fd/" + std::to_string(fd);
  try {
    adit::drivers::PcapReader reader(path);
    adit::drivers::UdpDatagram d;
    std::uint64_t n = 0;
    while (reader.next(d)) {
      if (d.payload.size() > 65535) __builtin_trap();
      ++n;
    }
    if (reader.stats().datagrams != n) __builtin_trap();
  } catch (const adit::InputError&) {
  }
  close(fd);
  return 0;
}
