#include "process_memory.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>

namespace adit::tools {

double resident_mb() {
  // A plain read: cheap enough to sample once per scan.
  std::FILE* statm = std::fopen("/proc/self/statm", "r");
  if (statm == nullptr) return 0.0;
  long size = 0;
  long resident = 0;
  const int fields = std::fscanf(statm, "%ld %ld", &size, &resident);
  std::fclose(statm);
  if (fields != 2) return 0.0;
  return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

double peak_resident_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // KiB on Linux
}

}  // namespace adit::tools
