// The live grid's stream: changed patches, then a share of the rest.
// (grid_publisher.hpp)
#include "adit/daemon/grid_publisher.hpp"

#include <cmath>

#include "adit/protocol/grid_codec.hpp"

namespace adit::daemon {

GridPublisher::GridPublisher(GridPublisherOptions options, GridPatchSink& sink)
    : options_(std::move(options)), sink_(sink) {}

void GridPublisher::reset(std::string session_id) {
  session_id_ = std::move(session_id);
  patches_.clear();
  dirty_.clear();
  refresh_cursor_ = {};
}

void GridPublisher::update(const GridPatchUpdate& update) {
  const Key key{update.x, update.y};
  grid_patch_t& m = patches_[key];
  m.utime = update.utime;
  m.schema = 1;
  m.payload_id = options_.payload_id;
  m.session_id = session_id_;
  m.resolution_m = update.resolution_m;
  m.patch_cells = update.patch_cells;
  m.patch_x = update.x;
  m.patch_y = update.y;
  m.version = update.version;
  m.n_patches = update.patches;
  const std::vector<std::uint8_t> frame = protocol::encode_grid_cells(update.cells);
  m.data.assign(frame.begin(), frame.end());
  m.size = static_cast<std::int32_t>(m.data.size());
  dirty_.insert(key);
}

void GridPublisher::send(grid_patch_t& message) {
  message.n_patches = static_cast<std::int32_t>(patches_.size());
  sink_.send(message);
  ++counts_.patches_sent;
  counts_.bytes_sent += static_cast<std::uint64_t>(message.getEncodedSize());
}

void GridPublisher::tick(Clock::time_point now) {
  if (patches_.empty() || now - last_send_ < std::chrono::duration<double>(options_.period_s)) return;
  last_send_ = now;
  for (const Key& key : dirty_) send(patches_.at(key));
  // Every patch again within refresh_s: this period's share, after the cursor.
  auto share = static_cast<std::size_t>(
      std::ceil(static_cast<double>(patches_.size()) * options_.period_s / options_.refresh_s));
  share = std::min(share, patches_.size() - dirty_.size());
  auto it = patches_.upper_bound(refresh_cursor_);
  for (std::size_t sent = 0; sent < share;) {
    if (it == patches_.end()) it = patches_.begin();
    if (!dirty_.contains(it->first)) {
      send(it->second);
      ++counts_.refreshes_sent;
      ++sent;
    }
    refresh_cursor_ = it->first;
    ++it;
  }
  dirty_.clear();
}

}  // namespace adit::daemon
