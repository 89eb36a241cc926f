#pragma once
// Georeferencing a map to control points: the rigid (or similarity) transform
// taking the session's map frame onto the site's grid (E, N, H), fitted on the
// targets found in the map (`adit targets find`) and the control points a
// total station measured on the same targets (control_points.hpp).
//
// Matching: by id when every control id is a target id; by geometry when none
// is (pairwise distances are the same in both frames, up to the map's error);
// a file where some ids match and some do not is refused (a typo would
// otherwise pair the wrong points silently).
//
// The fit is Umeyama's closed form (align.hpp). A plain fit spreads a
// control point's blunder over all of them (four points, one 10 cm off: each
// residual a few centimetres), so each point is also checked by leaving it out:
// its residual against the fit on the others (the "check point" residual
// survey software prints). Points are removed one at a time, the worst
// leave-one-out residual first, while it exceeds the tolerance and more than
// three remain: Baarda's iterative data snooping, with the leave-one-out
// residual in place of the standardised one (W. Baarda, "A testing procedure
// for use in geodetic networks", Netherlands Geodetic Commission, 1968).
//
// Bad input (adit::InputError naming the control file, and the line where one
// applies): an id not among the targets, fewer than three matches, points
// whose distances are 3.28 times the map's (feet read as metres, or the
// reverse), E and N swapped (the fit only works mirrored: a rigid fit leaves
// large residuals, or turns the map upside down when the targets lie near one
// level), points that do not fit at all or only by tilting the map, an ambiguous geometric match, points on one line.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "adit/eval/align.hpp"
#include "adit/eval/control_points.hpp"
#include "adit/eval/targets.hpp"

namespace adit::eval {

enum class MatchBy { automatic, id, geometry };

struct GeorefOptions {
  bool with_scale = false;
  // Turn the map about the vertical only (4 parameters, 5 with scale): a tilt
  // fitted on a few control points carries the map's height drift far from
  // them. It trusts the map's z: aditd levels its exports by the odometry's
  // gravity (decision 060); without an IMU or accelerometer their z is the
  // first pose's, tilted as the payload started (decision 059).
  bool level = false;
  double tolerance_m = 0.05;        // a residual or leave-one-out residual above this is flagged
  double match_tolerance_m = 0.25;  // pairwise distances agree within this + 0.2 % of the distance
  // aditd's map has z near up (gravity's, or the first pose's within the
  // payload's starting tilt): a fit that tilts it more than this is a wrong match or a mirror.
  double max_tilt_deg = 10.0;
  MatchBy match = MatchBy::automatic;
};

struct ControlResidual {
  std::string id;         // the control point's
  std::string target_id;  // the map target it is matched to
  std::size_t line = 0;   // in the control file
  Eigen::Vector3d delta = Eigen::Vector3d::Zero();  // control - fitted target: dE, dN, dH
  double distance = 0.0;
  // Against the fit on the other points in the fit; nullopt when that fit is
  // not determined (three points in the fit).
  std::optional<Eigen::Vector3d> loo_delta;
  bool in_fit = true;    // false: left out by the data snooping
  bool flagged = false;  // residual or leave-one-out residual above the tolerance
};

struct Georeference {
  Similarity fit;                        // map frame -> site (E, N, H)
  std::string matched_by;                // "id" or "geometry"
  std::vector<ControlResidual> points;   // the matched control points, in file order
  std::vector<std::string> unmatched;    // control ids without a target (geometry only)
  double rms_m = 0.0;                    // 3D rms of the residuals of the points in the fit
};

Georeference georeference(const ControlFile& control, const std::vector<Target>& targets, const GeorefOptions& options);

// For each control point, the index of its target, or -1: the largest set of
// pairs whose pairwise distances agree within tolerance_m + 0.2 % (grown
// greedily from every pair of pairs that agrees; ties go to the smaller sum
// of disagreements). Empty input gives all -1.
std::vector<int> match_by_geometry(const std::vector<Eigen::Vector3d>& control,
                                   const std::vector<Eigen::Vector3d>& targets, double tolerance_m);

}  // namespace adit::eval
