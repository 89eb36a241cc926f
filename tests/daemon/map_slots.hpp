#pragma once
// A mapping stage's input slot with room for `max_points` points, for the
// Handoff<MapSlot> a test feeds a MappingStage through.

#include <cstddef>
#include <functional>

#include "adit/daemon/pipeline_items.hpp"

namespace adit::test {

inline std::function<daemon::MapSlot()> map_slot_with_room(std::size_t max_points) {
  return [max_points] {
    daemon::MapSlot s;
    s.points.reserve(max_points);
    s.times_s.reserve(max_points);
    s.intensities.reserve(max_points);
    return s;
  };
}

}  // namespace adit::test
