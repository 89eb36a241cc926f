#pragma once
// Scan Context: a keyframe's place descriptor (Kim & Kim, "Scan Context:
// Egocentric Spatial Descriptor for Place Recognition within 3D Point Cloud
// Map", IROS 2018), written from the paper.
//
// The scan, in the body frame (z up), is cut into N_r rings of equal width up
// to L_max and N_s sectors of equal azimuth; each bin holds the highest point
// that falls in it (paper §III-A, eq. 1-2), here as its height above the
// lowest point of the scan plus 1 m, so that an empty bin (0) differs from a
// bin at the floor. A turn of the body about z shifts the columns (sectors)
// and leaves the rings: two descriptors are compared at every column shift
// and the best shift is the relative yaw (§III-B, eq. 5-6), so a drift driven
// back the other way (a 180° shift) matches like one driven the same way.
// The ring key, each ring's share of occupied bins (§III-C, eq. 7-8), does
// not depend on yaw at all and orders the candidates cheaply.
//
// A tunnel is symmetric: a scan matches itself turned 180° nearly as well as
// unturned. `compare` therefore returns the best shift and the best shift at
// least `kAlternativeSeparationRad` away from it; verification registers from
// both (slam/loop_verification.hpp). Why Scan Context:
// docs/decisions/021-loop-closure-scan-context.md.

#include <span>

#include <Eigen/Core>

namespace adit::slam {

struct ScanContextConfig {
  int rings = 20;             // N_r (the paper's value)
  int sectors = 60;           // N_s (6° each; the paper's value)
  float max_radius_m = 40.0F; // L_max: a VLP-16 in a mine sees walls within a few tens of metres
};

struct ScanContext {
  Eigen::MatrixXf bins;      // rings × sectors, height above the scan's lowest point + 1 m; 0 = empty
  Eigen::VectorXf ring_key;  // per ring, the share of its sectors that hold a point
};

// `points` in the body frame, z up.
ScanContext make_scan_context(std::span<const Eigen::Vector3f> points, const ScanContextConfig& config = {});

struct ScanContextMatch {
  double distance = 1.0;        // mean cosine distance between matched columns, 0 (same) to 1 (paper eq. 5)
  double yaw_rad = 0.0;         // the yaw that turns `query`'s body onto `candidate`'s: R_candidate⁻¹·R_query about z
  double alternative_distance = 1.0;  // the best shift at least kAlternativeSeparationRad from `yaw_rad`
  double alternative_yaw_rad = 0.0;
};

inline constexpr double kAlternativeSeparationRad = 1.5707963267948966;  // 90°

// Distance at every column shift, the best two (eq. 6). Columns empty in both
// are left out of the mean, as the paper does.
ScanContextMatch compare(const ScanContext& query, const ScanContext& candidate);

// Euclidean distance between ring keys: the cheap first stage of the search.
inline float ring_key_distance(const Eigen::VectorXf& a, const Eigen::VectorXf& b) { return (a - b).norm(); }

}  // namespace adit::slam
