#pragma once
// LiDAR odometry, one scan at a time: predict, deskew, downsample, register
// against the local map, update the map (the pipeline of KISS-ICP, Vizzo et
// al. 2023, with point-to-plane registration, a pose prior from wheel
// odometry or constant velocity, and degeneracy handling; see registration.hpp).
//
// Every buffer is sized at construction from OdometryConfig, so process()
// allocates nothing, takes no lock and never throws: bad scans come back with
// valid = false and a reason, and the pose is held on the prediction.

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "adit/slam/adaptive_threshold.hpp"
#include "adit/slam/deskew.hpp"
#include "adit/slam/gravity.hpp"
#include "adit/slam/imu_sample.hpp"
#include "adit/slam/inertial_filter.hpp"
#include "adit/slam/map_insertion.hpp"
#include "adit/slam/registration.hpp"
#include "adit/slam/standstill.hpp"
#include "adit/slam/voxel_downsample.hpp"
#include "adit/slam/voxel_hash_map.hpp"

namespace adit::slam {

struct OdometryConfig {
  float min_range_m = 0.5F;
  float max_range_m = 100.0F;
  float map_voxel_m = 0.5F;              // local map voxel; the scan is kept at half of it
  float registration_voxel_m = 0.75F;    // points used for registration (1.5 × map voxel), at the finest
  // Downsampling adapts to the sensor: a scan that gives more registration
  // points than this at its voxel makes the next scan's voxel coarser by
  // sqrt(points / target) (a surface's points go as 1/voxel²), and one that
  // gives fewer makes it finer again, down to registration_voxel_m. A VLP-16
  // stays below it (at most 1 878 points on the simulated mine sessions), so
  // its scans keep 0.75 m; a 64-beam scan (3 850 points at 0.75 m on
  // hdl64-urban-22) is brought to about this many, which bounds the plane
  // searches, most of the time per scan. KISS-ICP scales its voxel with the
  // maximum range instead (Vizzo et al. 2023, §III-B). Why 2 500:
  // docs/decisions/011-adaptive-registration-voxel.md.
  std::size_t target_registration_points = 2500;
  float max_registration_voxel_m = 2.0F;
  std::size_t map_capacity_voxels = std::size_t{1} << 17;
  // Minimum distance between two points of one map voxel (0 = none: a voxel
  // keeps its first VoxelHashMap::kMaxPointsPerVoxel points, the rings of the
  // few scans that first saw it, and point-to-plane then prefers those scans'
  // attitude). KISS-ICP ≥ 1.0 refuses points closer than voxel / sqrt(20)
  // (0.112 m here), which let a wheel spin through on a simulated drive and
  // cost the featureless drift's map; why 0.08 m:
  // docs/decisions/001-map-point-spacing.md.
  float map_point_spacing_m = 0.08F;
  // The local map drops voxels beyond max_range_m once the sensor has moved
  // this far since it last did, not after every scan: the pass reads the
  // whole table (2 MB, 3.6 M instructions per scan, 7 % of a 64-beam scan's
  // work), while the voxels it would free after a few cm of motion lie at the
  // edge of the range, where few scan points are. So the map reaches at most
  // max_range_m + map_removal_step_m.
  float map_removal_step_m = 1.0F;
  // A scan enters the local map only once the body has moved since the last
  // scan that did (map_insertion.hpp).
  MapInsertionStep map_insertion;
  std::size_t max_scan_points = 400'000; // beyond this a scan is cut (counted)
  std::size_t min_registration_points = 100;
  double initial_threshold_m = 2.0;
  double min_motion_m = 0.1;
  // Without a known velocity the registration also starts from offsets along
  // the body's x and y, every start_search_step_m up to what
  // max_start_speed_mps covers between the two scans (decision 012).
  double max_start_speed_mps = 10.0;
  double start_search_step_m = 0.5;
  // The search's winner must beat the prediction's registration by this many
  // √n correspondences (n the prediction's): more than counting noise (decision 040).
  double start_search_noise_sigmas = 3.0;
  // A turn the prediction missed: when the registration explains fewer than
  // min_correspondence_share of the last scan's correspondences, it is also
  // started from the prediction turned about the body's z, every
  // rotation_search_step_rad up to what max_turn_rate_radps covers between
  // the two scans (0: no search), at most max_rotation_starts starts (a
  // search's cost: a slow core must not stall the pipeline; decision 042).
  // One start pulls in from about ±3° on real HDL-64 scans, hence the step.
  // 5 rad/s: a hand-held turn of 120°/s reversed within one interval. A
  // search starts a registration only while the odometry keeps up with its
  // input (Odometry's `keeping_up`): on a core too slow for the scan rate,
  // dropped scans made the predictions miss, each miss a search, and the
  // searches' cost dropped more scans (decision 044).
  double max_turn_rate_radps = 5.0;
  double rotation_search_step_rad = 0.1;
  int max_rotation_starts = 16;
  // Lost: after the searches the registration still matches fewer than
  // lost_correspondence_share of the last tracked scan's correspondences.
  // The scan is held on the prediction and kept out of the map, and the next
  // one is judged against the last tracked scan again. After max_lost_scans
  // in a row the scene has changed, not the fit: tracking restarts from the
  // registration (decision 043).
  double lost_correspondence_share = 0.5;
  int max_lost_scans = 10;
  double max_scan_gap_s = 1.0;           // a longer gap forgets the velocity
  // The constant-velocity prediction's standard deviation per scan, used as a
  // weak prior so that degenerate directions stay anchored to the prediction.
  double constant_velocity_sigma_m = 0.5;
  double constant_velocity_sigma_rad = 0.2;
  // A platform whose acceleration is bounded (a wheeled robot's traction)
  // departs from a constant-velocity prediction by at most ½·a·dt² in a scan;
  // when set (> 0), that is the prediction's translation σ instead of
  // constant_velocity_sigma_m. It carries a featureless drift through a
  // wheel dropout (docs/decisions/035-traction-bounded-prediction.md).
  double max_acceleration_mps2 = 0.0;
  // A wheel prior whose registration matches fewer than this share of the
  // previous scan's correspondences is checked against constant velocity.
  double min_correspondence_share = 0.7;
  // A wheel prior this far from the constant-velocity prediction in one scan
  // (a yaw acceleration of 150°/s² at 10 Hz, or 1.5 g) is checked against
  // constant velocity too: a spinning wheel can keep the scan overlapping.
  double max_wheel_disagreement_rad = 0.026;
  double max_wheel_disagreement_m = 0.15;
  // Constant velocity replaces the wheels only when it explains this share
  // more of the scan: where the scan cannot tell (a degenerate direction
  // keeps each registration's own prior) a tie must not hand the pose to a
  // velocity that may still carry a spun wheel's false turn.
  double wheel_rejection_margin = 0.05;
  // Estimate the body velocity over each sweep with the pose (continuous-time
  // registration, see SweepMotion) instead of deskewing with the prediction's.
  // The prior on it, per sweep: the prediction's velocity with these σ.
  bool estimate_sweep_velocity = true;
  double sweep_velocity_sigma_mps = 0.5;
  double sweep_velocity_sigma_radps = 0.5;
  // Gravity (ScanInput::gravity) holds roll and pitch: scan-to-map odometry
  // carries its tilt on through its own map
  // (docs/decisions/008-accelerometer-gravity-prior.md). The
  // odometry frame's up is the mean of the measured ups over this long from
  // the first, each placed by its scan's pose and weighted by 1/σ²; then it
  // is fixed. It is meant for the second a crew holds still after starting:
  // once the gravity prior holds the poses to this up, later readings placed
  // by those poses only repeat it, so a longer mean cannot correct a frame
  // taken while moving off (docs/decisions/003-gravity-settle.md).
  double gravity_settle_s = 1.0;
  RegistrationConfig registration;
  // With a gyroscope (ScanInput::imu), LiDAR-inertial odometry: the IMU
  // predicts and deskews, the scan corrects (inertial_filter.hpp).
  InertialConfig inertial;
  // σ of one point-to-plane residual against the IMU's prediction: between
  // LiDAR-only's 1 m (registration.point_sigma_m, which lets the wheels keep
  // a drift's axis) and FAST-LIO2's 0.0316 m (0.001 m², its released
  // configuration). Tighter, a drift's biased axis (decision 010) drags the
  // filter's velocity and gravity with it; looser, the scan is too weak to
  // teach the filter its gyroscope's bias. 0.03–0.3 m track every drive of
  // docs/decisions/020-lio-noise-and-scan-weight.md; 0.1 m in their middle.
  double inertial_point_sigma_m = 0.1;
  // With the IMU: a zero-velocity update when the scan shows the body still
  // (standstill.hpp).
  StandstillConfig standstill;
  // Anchored to a prior map (anchor_to_prior): σ of one point-to-plane
  // residual against the prior. Tighter than LiDAR-only's 1 m against the
  // local map: that σ is loose because the scan and the local map share the
  // rings' sampling pattern (decision 010), which a prior sampled from a model
  // or another session's map does not; and the prior is what must overrule
  // the wheels' scale error and the local map's drift. FAST-LIO2's map
  // residuals use 0.0316 m (0.001 m²). Why 0.03 m:
  // docs/decisions/048-prior-map-in-the-odometry.md.
  double prior_map_sigma_m = 0.03;
  // Every this many registration points looks up its plane in the prior (the
  // prior's searches are most of what anchoring costs per scan; decision 048).
  int prior_map_stride = 1;
};

// Body motion since the previous scan from wheel odometry, with its
// covariance in the body frame (tangent space at the motion, [v; ω]).
struct MotionPrior {
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Identity();
};

struct ScanInput {
  std::int64_t stamp_ns = 0;                  // the scan's start time
  std::span<const Eigen::Vector3f> points;    // body frame, as measured
  std::span<const float> times_s;             // per point, after stamp; empty = no deskewing
  // Gravity's up in the body frame over the sweep (slam::measured_up), or
  // nullopt without an IMU.
  std::optional<UpMeasurement> gravity = std::nullopt;
  // IMU readings with the gyroscope's rate (body frame, ascending), from at
  // or before the previous scan's stamp to past this sweep's end: the
  // odometry is then LiDAR-inertial. Empty, or not covering that: LiDAR only.
  std::span<const ImuSample> imu = {};
};

enum class OdometryStatus : std::uint8_t {
  ok,
  first_scan,         // the map starts here
  too_few_points,     // held on the prediction
  time_went_back,     // scan ignored
  degenerate,         // valid, but some directions come from the prior only
  lost,               // the fit collapsed: held on the prediction, kept out of the map
  relocalised,        // valid: the first scan tracked again after lost ones
};

std::string_view to_string(OdometryStatus status);

struct OdometryResult {
  std::int64_t stamp_ns = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // body in the odometry frame
  Matrix6d covariance = Matrix6d::Identity();
  OdometryStatus status = OdometryStatus::ok;
  bool valid = false;       // the pose comes from registration
  bool wheel_rejected = false;  // the wheel prior disagreed with the scan (or the IMU); it was not used
  bool inertial = false;        // the IMU predicted and deskewed this scan
  bool standstill = false;      // the body appeared still: the filter took a zero-velocity update
  bool search_cut = false;      // a rotation or start search stopped short: the odometry was behind its input
  Vector6d sweep_velocity = Vector6d::Zero();  // body twist per second over the scan, as deskewed
  RegistrationResult registration;
  std::size_t input_points = 0;
  std::size_t registration_points = 0;
  float registration_voxel_m = 0.0F;  // the voxel the registration points were downsampled at
};

// Whether a wheel motion over dt departs from the constant-velocity
// prediction by more than config.max_wheel_disagreement_* (a spinning wheel).
bool wheel_motion_implausible(const Eigen::Isometry3d& wheel_delta, const Vector6d& velocity, double dt,
                              const OdometryConfig& config);

class Odometry {
 public:
  // `keeping_up`, when given, says whether the odometry keeps up with its
  // input (no scan waiting behind this one in a live stream); the searches
  // start a registration only while it returns true (decision 044). Empty:
  // always (a file replayed as fast as it goes, a test).
  explicit Odometry(const OdometryConfig& config, std::function<bool()> keeping_up = {});

  OdometryResult process(const ScanInput& scan, const std::optional<MotionPrior>& wheel = std::nullopt);

  // From the next scan on, registers every scan against a prior map as well
  // (PriorMapTerm): `prior_index` (index_prior_map; it must outlive this
  // odometry or the next anchor), its frame placed at `prior_from_odometry`
  // (global localisation). The poses stay in the odometry frame; the prior
  // holds them where the prior says, so prior_from_odometry·pose is the pose
  // in the prior's frame. Allocates the prior's plane buffer: call it once
  // localised, not per scan.
  // Its residuals count with OdometryConfig::prior_map_sigma_m.
  void anchor_to_prior(const VoxelHashMap& prior_index, const Eigen::Isometry3d& prior_from_odometry);
  // Back to the local map alone (a prior found wrong, a session's end).
  void release_prior();
  // The prior's frame, while anchored.
  std::optional<Eigen::Isometry3d> prior_from_odometry() const;

  // Gravity's up in the odometry frame, once measured: the LiDAR-inertial
  // filter's, or the accelerometer's settled mean (OdometryConfig::gravity_settle_s).
  std::optional<Eigen::Vector3d> up() const;

  const VoxelHashMap& local_map() const { return map_; }
  // The IMU filter's state (biases, gravity, velocity), meaningful once a
  // result had `inertial` set.
  const InertialFilter& inertial() const { return inertial_; }
  // The last scan, deskewed, downsampled at the map resolution, in the
  // odometry frame: what mapping accumulates. Valid until the next process().
  std::span<const Eigen::Vector3f> last_registered_points() const { return registered_; }
  // An inertial scan's motion over its sweep, from its start, as the IMU had
  // it after the scan's update: what its map points were deskewed with.
  std::span<const TimedPose> sweep_motion() const { return sweep_motion_; }
  static constexpr std::size_t kSweepMotionCapacity = 256;  // instants reserved (the IMU's over a sweep)
  const OdometryConfig& config() const { return config_; }

 private:
  OdometryConfig config_;
  std::function<bool()> keeping_up_;
  VoxelHashMap map_;
  VoxelDownsampler downsampler_;
  Deskewer deskewer_;
  AdaptiveThreshold threshold_;
  std::vector<Eigen::Vector3f> deskewed_;
  std::vector<Eigen::Vector3f> frame_;       // map-resolution points, as measured
  std::vector<float> frame_times_;
  std::vector<Eigen::Vector3f> source_;      // registration-resolution points, as measured
  std::vector<float> source_times_;
  std::vector<Eigen::Vector3f> source_deskewed_;  // registration's scratch
  std::vector<Eigen::Vector3f> registered_;
  std::vector<MapPlane> planes_;             // registration's per-point planes
  PriorMapTerm prior_map_;                   // index null: not anchored to a prior; planes: see prior_term()
  std::vector<MapPlane> prior_planes_;       // registration's per-point planes in the prior
  // prior_map_ with prior_planes_ (a copy of the odometry keeps its own),
  // weighted against residuals of σ `local_sigma_m` (the registration's point_sigma_m).
  PriorMapTerm prior_term(double local_sigma_m);
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();
  Vector6d velocity_ = Vector6d::Zero();     // body twist per second, between the last two sweep middles
  Eigen::Isometry3d start_to_mid_ = Eigen::Isometry3d::Identity();  // pose_ to the middle of its sweep
  double mid_offset_s_ = 0.0;                // time from pose_ to the middle of its sweep
  std::int64_t last_stamp_ns_ = 0;
  bool started_ = false;
  bool reacquire_ = false;       // the next registration uses the initial threshold
  bool velocity_known_ = false;  // a registration has measured the motion since the start or the last gap
  double last_correspondences_ = 0.0;  // the last tracked scan's
  int lost_scans_ = 0;                 // in a row, up to now
  float registration_voxel_m_;  // this scan's, adapted from the last (see OdometryConfig)
  Eigen::Vector3d removed_far_at_ = Eigen::Vector3d::Zero();  // sensor position at the last remove_far
  Eigen::Isometry3d added_at_ = Eigen::Isometry3d::Identity();  // pose of the last scan the map took
  bool keeping_up() const { return !keeping_up_ || keeping_up_(); }
  // LiDAR-inertial odometry (odometry_inertial.cpp).
  // Whether the scan's IMU readings can carry the filter over it: then the
  // filter is propagated to the scan and its sweep's motion predicted.
  bool predict_inertial(const ScanInput& scan, double sweep_s);
  // Registers the scan from the IMU's prediction (and the wheels'), updates
  // the filter and the map.
  void register_inertial(const ScanInput& scan, const std::optional<MotionPrior>& wheel, OdometryResult& result);
  // (Re)starts the filter at the current pose when the scan's IMU readings
  // allow it: gravity from their mean specific force, the velocity as known.
  void start_inertial(const ScanInput& scan, const Matrix6d& body_covariance);
  InertialFilter inertial_;
  bool inertial_started_ = false;
  Eigen::Vector3d updated_velocity_ = Eigen::Vector3d::Zero();  // the filter's after its last update (world)
  std::vector<TimedPose> sweep_motion_;  // the body over this sweep, from the scan start
  RegistrationConfig inertial_registration_;
  // Places deskewed_ at pose_ in the map once the body has moved since the
  // last scan it took (map_insertion), dropping what is out of range.
  void add_deskewed_to_map();
  // Up in the odometry frame (see OdometryConfig::gravity_settle_s): the
  // weighted sum of the measured ups placed by their poses, until settled.
  void settle_up(const UpMeasurement& gravity, std::int64_t stamp_ns);
  Eigen::Vector3d up_sum_ = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> up_frame_;
  std::int64_t first_up_ns_ = 0;
};

}  // namespace adit::slam
