// Writes every UDP payload of the given captures to DIR/<capture>-<n>.bin:
// seeds for the packet fuzzers from the real recordings, without committing
// binary corpora. Usage: fuzz_seeds_from_pcap DIR FILE.pcap...
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "adit/drivers/pcap_reader.hpp"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s DIR FILE.pcap...\n", argv[0]);
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  for (int i = 2; i < argc; ++i) {
    adit::drivers::PcapReader reader(argv[i]);
    adit::drivers::UdpDatagram d;
    for (int n = 0; reader.next(d); ++n) {
      const auto name = std::filesystem::path(argv[i]).stem().string() + "-" + std::to_string(n) + ".bin";
      std::ofstream(dir / name, std::ios::binary)
          .write(reinterpret_cast<const char*>(d.payload.data()), static_cast<std::streamsize>(d.payload.size()));
    }
  }
  return 0;
}
