#pragma once
// A prior-map anchor taken only when two tries agree: a try's localise()
// result is checked against the rivals it saw, but a floor nearly symmetric
// under a half turn, where the place seen was not built as designed, can fit
// a wrong pose better than the right one in one second of scans
// (docs/decisions/053-prior-localisation-confirmed.md). Another second later,
// seen from elsewhere, a wrong pose rarely repeats; two tries agreeing is the
// pairwise consistency the loop closer asks of its loops too. Used by aditd's
// prior localiser and `adit bench prior-map` (unless --no-confirm).

#include <optional>

#include <Eigen/Geometry>

#include "adit/slam/global_localisation.hpp"

namespace adit::slam {

// The acceptance for each try of a confirmed pair: `base` with its overlap
// threshold at 0.85 instead of a lone try's 0.9. Two tries that must agree
// guard against a wrong pose together; a lone try's 0.9 refused most of the
// right hand-held poses (overlap 0.87-0.90: furniture, doors) (decision 053).
LocalisationConfig confirmed_localisation(LocalisationConfig base = {});

class AnchorConfirmation {
 public:
  explicit AnchorConfirmation(const LocalisationConfig& config = {}) : config_(config) {}

  // A try found `anchor` (prior_from_odometry) for a cloud gathered in the
  // frame `cloud_in_odometry`. True when the anchor found before places
  // that frame as this one does (within the config's rival_m and rival_rad,
  // the distances at which localise() calls two poses rivals): take it.
  // Otherwise this anchor replaces the earlier one and waits for the next try.
  bool agrees(const Eigen::Isometry3d& anchor, const Eigen::Isometry3d& cloud_in_odometry);

  bool waiting() const { return candidate_.has_value(); }

 private:
  LocalisationConfig config_;
  std::optional<Eigen::Isometry3d> candidate_;
};

}  // namespace adit::slam
