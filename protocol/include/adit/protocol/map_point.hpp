#pragma once
// One point of the map as tiles carry it and exports write it.

namespace adit::protocol {

struct MapPoint {
  double x = 0;  // m, map frame
  double y = 0;
  double z = 0;
  float intensity = 0;  // sensor units, 0..65535 survive tile coding
  double time = 0;      // s since the Unix epoch (tiles: when the tile version was made)
};

}  // namespace adit::protocol
