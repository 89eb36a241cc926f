#pragma once
// Moving objects out of a finished session's map: its scans are read again
// from the raw recording (session_scans.hpp) and every map point that scans
// saw through (see_through.hpp) is taken out of the map, before the
// occupancy, the grid and the pictures are made from it.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "adit/products/see_through.hpp"
#include "adit/products/session_map.hpp"

namespace adit::products {

struct MovingObjectsReport {
  bool ran = false;
  std::string skipped_because;                  // why not, when it did not run
  std::size_t scans = 0, scans_used = 0;
  std::size_t candidates = 0;                   // map points tested
  std::size_t suspects = 0;                     // of those, seen through in the coarse pass
  std::size_t removed = 0;
  std::vector<protocol::MapPoint> removed_points;
};

// Removes the dynamic points from `inputs.points` (order kept) and returns
// them in the report. `keep[i]` = 1: never removed (e.g. ground), empty: all
// may be. Throws adit::InputError for an unreadable recording or configuration.
MovingObjectsReport remove_moving_objects(const std::filesystem::path& session_dir, SessionInputs& inputs,
                                          std::span<const std::uint8_t> keep, const SeeThroughOptions& options);

}  // namespace adit::products
