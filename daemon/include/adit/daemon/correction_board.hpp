#pragma once
// The loop closure's latest map←odometry correction through time
// (slam/correction_track.hpp), handed from the loops thread, which posts one
// after each graph optimisation, to the mapping thread (live tiles placed by
// the graph, docs/LOOPS.md "Live tiles") and the status (frame_t). Posted a
// few times a session, read once a second or two: a mutex around a shared
// pointer to an immutable track.

#include <memory>
#include <mutex>

#include "adit/slam/correction_track.hpp"

namespace adit::daemon {

class CorrectionBoard {
 public:
  void post(slam::CorrectionTrack track) {
    auto posted = std::make_shared<const slam::CorrectionTrack>(std::move(track));
    const std::lock_guard lock(mutex_);
    latest_ = std::move(posted);
  }
  // nullptr until the first post: no correction (identity).
  std::shared_ptr<const slam::CorrectionTrack> latest() const {
    const std::lock_guard lock(mutex_);
    return latest_;
  }

 private:
  mutable std::mutex mutex_;
  std::shared_ptr<const slam::CorrectionTrack> latest_;
};

}  // namespace adit::daemon
