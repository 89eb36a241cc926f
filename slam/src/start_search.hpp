#pragma once
// The start search of Odometry (docs/decisions/012-start-search.md): with no
// velocity known, the registration is also started from offsets along the
// body's x and y axes, every `step_m` up to `reach_m`, nearest first, and an
// offset's result replaces the best one when it explains clearly more of the
// scan (`margin` more correspondences). Shared by the LiDAR-only step
// (odometry.cpp) and the LiDAR-inertial one (odometry_inertial.cpp).
//
// The winner must also beat the prediction's own registration by more than
// counting noise: `noise_sigmas`·√n correspondences, n the prediction's
// count (a count's Poisson spread). Against a map of one scan taken at rest
// both match a few dozen to a few hundred points, and a 5 % margin is a tie
// (decision 040).

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Core>

#include "adit/slam/registration.hpp"

namespace adit::slam {

// The searches' last rule: `best` stays only when it matches more than
// `noise_sigmas`·√n correspondences more than `predicted` (n its count);
// otherwise the prediction's registration is kept.
inline void keep_beyond_counting_noise(const RegistrationResult& predicted, double noise_sigmas,
                                       RegistrationResult& best) {
  const double n = static_cast<double>(predicted.correspondences);
  if (static_cast<double>(best.correspondences) - n <= noise_sigmas * std::sqrt(n)) best = predicted;
}

// The rule for a rival registration (a search's start, the wheels' check of
// decision 006): it replaces `best` only when it explains clearly more of the
// scan, `margin` more correspondences.
inline bool explains_clearly_more(const RegistrationResult& alternative, const RegistrationResult& best,
                                  double margin) {
  return static_cast<double>(alternative.correspondences) > (1.0 + margin) * static_cast<double>(best.correspondences);
}

// One start of a search: registered from `start` and kept by the rule above,
// if `go_on()` allows it; false (nothing tried) when it does not.
template <typename GoOn, typename RegisterFrom, typename Start>
bool try_start(GoOn& go_on, RegisterFrom& register_from, const Start& start, double margin, RegistrationResult& best) {
  if (!go_on()) return false;
  const RegistrationResult alternative = register_from(start);
  if (explains_clearly_more(alternative, best, margin)) best = alternative;
  return true;
}

// `register_from(offset)` registers from the prediction moved by `offset`
// (m, body x and y) and returns the result. Each start waits for `go_on()`:
// when it says false (the odometry fell behind its input, decision 044) the
// search stops with what it has, and returns false. True: every start tried.
template <typename GoOn, typename RegisterFrom>
bool search_start(double reach_m, double step_m, double margin, double noise_sigmas, GoOn&& go_on,
                  RegisterFrom&& register_from, RegistrationResult& best) {
  const RegistrationResult predicted = best;
  const auto steps = static_cast<int>(std::floor(reach_m / step_m + 1e-9));
  bool complete = true;
  for (int k = 1; k <= steps && complete; ++k) {
    const double d = k * step_m;
    for (const Eigen::Vector2d& offset :
         {Eigen::Vector2d(d, 0.0), Eigen::Vector2d(-d, 0.0), Eigen::Vector2d(0.0, d), Eigen::Vector2d(0.0, -d)}) {
      complete = try_start(go_on, register_from, offset, margin, best);
      if (!complete) break;
    }
  }
  keep_beyond_counting_noise(predicted, noise_sigmas, best);
  return complete;
}

// The same over turns: the registration is also started from the prediction
// turned about the body's z axis by ±`step_rad`, ±2·`step_rad`, … up to
// `reach_rad` (at most half a turn), nearest first, with the same rule for
// the winner. Every turn is tried: stopping at the first that fits as well
// as the scans before did takes a nearer wrong fit on real scans (decision
// 042). `register_from(yaw)` registers from the prediction turned by yaw;
// `go_on` and the result as search_start's.
template <typename GoOn, typename RegisterFrom>
bool search_rotation(double reach_rad, double step_rad, double margin, double noise_sigmas, GoOn&& go_on,
                     RegisterFrom&& register_from, RegistrationResult& best) {
  const RegistrationResult predicted = best;
  const auto steps = static_cast<int>(std::floor(std::min(reach_rad, std::numbers::pi) / step_rad + 1e-9));
  bool complete = true;
  for (int k = 1; k <= steps && complete; ++k) {
    const double yaw = k * step_rad;
    for (const double turn : {yaw, -yaw}) {
      if (turn < 0.0 && yaw >= std::numbers::pi - 1e-9) continue;  // half a turn either way is one start
      complete = try_start(go_on, register_from, turn, margin, best);
      if (!complete) break;
    }
  }
  keep_beyond_counting_noise(predicted, noise_sigmas, best);
  return complete;
}

}  // namespace adit::slam
