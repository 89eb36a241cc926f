#pragma once
// The time every LCM message starts with: µs since the Unix epoch.

#include <chrono>
#include <cstdint>

namespace adit::protocol {

inline std::int64_t now_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace adit::protocol
