#include "bench_wheels.hpp"

#include <chrono>
#include <limits>
#include <thread>

#include "adit/common/error.hpp"
#include "adit/config/load.hpp"
#include "adit/daemon/extrinsics.hpp"
#include "adit/slam/lie.hpp"

namespace adit::tools {

WheelTrack load_wheel_track(const std::string& config_file) {
  const config::Config c = config::load_config(config_file);
  if (!c.can.enabled || !c.wheel_odometry.enabled || c.can.source != config::CanSource::candump)
    throw InputError(config_file, "wheel_odometry", "needs can.enabled with source candump and wheel_odometry.enabled");
  WheelTrack track;
  track.extrinsics = daemon::isometry_of(c.lidar.extrinsics);
  daemon::WheelFeed feed(c);
  feed.start({});
  constexpr double kEverything = std::numeric_limits<double>::infinity();
  while (!feed.finished()) {
    feed.drain_into(track.history, kEverything);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  feed.drain_into(track.history, kEverything);
  feed.stop();
  track.rejected = feed.stats().untrusted.load();
  track.slip_episodes = feed.stats().slip_episodes.load();
  track.samples = feed.stats().samples.load();
  if (!(track.history.latest() > -kEverything) || feed.stats().samples.load() < 2)
    throw InputError(c.can.log, "wheel_odometry", "fewer than 2 wheel samples decoded");
  track.distance = track.history.latest_distance();
  return track;
}

std::optional<slam::MotionPrior> wheel_prior(const WheelTrack& track, double t0, double t1) {
  std::optional<slam::MotionPrior> prior = track.history.prior(t0, t1);
  if (!prior) return std::nullopt;
  // Body frame to sensor frame: the motion by conjugation, the covariance by the adjoint.
  prior->delta = track.extrinsics.inverse() * prior->delta * track.extrinsics;
  const slam::Matrix6d Ad = slam::adjoint(track.extrinsics.inverse());
  prior->covariance = Ad * prior->covariance * Ad.transpose();
  return prior;
}

}  // namespace adit::tools
