// What the bundle fit (calib/bundle_fit.h) refines and how: typed switches per block,
// the robust loss and outlier rule, design tolerances and the Ceres solver's settings.
#pragma once

#include <ceres/solver.h>

#include <map>
#include <set>
#include <string>

#include "calib/board_warp.h"
#include "model/parameter_field.h"
#include "model/progress.h"
#include "model/sensor.h"

namespace omnical {

// Which parameters the fit moves, by the registry's groups (model/parameter_field.h);
// a held one keeps the start's value. Held entries of a block become a SubsetManifold,
// a block held whole is constant.
struct RefineOptions {
  bool focal = true;            // fx, fy of a pinhole; the scale of an orthographic lens
  bool principal_point = true;  // cx, cy
  bool distortion = true;       // k1, k2 of a pinhole
  bool tangential = true;       // p1, p2 of a pinhole (DefaultsFor holds them)
  bool m = true;                // lens-to-vertex distance
  bool tilt = true;
  bool decenter = true;
  bool shape = true;            // the profile's parameters
  bool poses = true;            // the target's pose in every view

  bool Refines(ParameterGroup group) const;
  // Holds the blocks named as the CLI's --fix and Python's fixed= name them: lens (focal,
  // principal point, distortion and tangential), lens_scale (focal), principal_point,
  // distortion, tangential, m, tilt, decenter, shape, poses. Empty, or "fixed: unknown
  // block '...' (...)".
  std::string Hold(const std::set<std::string>& names);
  // The held blocks by those names (lens for focal + principal point + both distortions).
  std::set<std::string> HeldNames() const;
  // Whether any sensor block is free (everything but the poses).
  bool RefinesSensor() const;
  // Every sensor block held, the poses free: views evaluated through a fitted sensor.
  static RefineOptions PosesOnly();
};

// The block name that holds a group (--fix, Python's fixed=, RefineOptions::Hold).
const char* HoldName(ParameterGroup group);

// Ceres' settings for the bundle fit: the poses eliminated (dense Schur), one thread,
// silent; the last stage stops at a relative cost change of 1e-12 or a step of 1e-15 of
// the parameter vector (every stage before it at Ceres' defaults). At 1e-12 of the cost
// the parameters sit ~1e-5 of a standard deviation from the minimum, which the covariance
// wants; 1e-16 added 20-40 iterations per noisy fit, many of them rejected steps. The step
// tolerance stays tight: exact observations drive the cost to 0, where only it stops the
// fit, and it is relative to the whole vector (fx ~ 2000 px), so 1e-12 left k2 at
// 1.4e-6 relative (tests/bundle_fit_harness_test.cc wants 1e-6).
ceres::Solver::Options DefaultSolverOptions();

// FitOptions::view_noise_weights' bounds: a view 10x noisier than the pool still counts.
constexpr double kMinViewWeight = 0.1;
constexpr double kMaxViewWeight = 10.0;

// The prior std of each corner's relief (FitOptions::fit_board_relief): a bent card's
// departure from the paraboloid is a fraction of a mm (the Mei set's, fitted: see
// docs/calibrate.md); 1 mm leaves that to the data and still settles the gauge.
constexpr double kBoardReliefStdMm = 1.0;

struct FitOptions {
  RefineOptions refine;
  double robust_loss_px = 1.0;  // robust scale in px (Cauchy, outlier removal, then Huber); 0 = plain least squares
  ceres::Solver::Options solver = DefaultSolverOptions();  // max_num_iterations is per stage
  bool compute_covariance = true;
  // A spline's c1 that only its knots leave undetermined (a near-gauge: no view sees the
  // axis) is held for the covariance at its fitted value, reported free with a NaN std
  // (FitResult::vertex_curvature_std_ratio; calib/bundle_fit.cc). False keeps the
  // near-singular covariance (tests compare the two).
  bool hold_weak_vertex_curvature = true;
  // Threads computing the corners' residuals and Jacobians (calib/parallel_evaluation.h);
  // Ceres' own work stays on one (solver.num_threads), so the fit is the same for any count.
  int threads = 1;
  // Outliers (robust mode): |residual| beyond max(outlier_floor_px, outlier_sigmas x the
  // bulk's sigma) are removed. The bulk: every corner within outlier_bulk_sigmas x the
  // median's sigma (|e| of a 2-D Gaussian has median 1.1774 sigma); its sigma per
  // coordinate sqrt(mean |e|^2 / 2). The median alone ignores the heavy tail real corners
  // have (a crumpled paper board, JPEG): 4 of its sigmas cut 15 of the real dev set's 480
  // corners (3.1 %), most of them on their junctions; 5 of the bulk's cut 4 (0.8 %). On
  // Gaussian noise the two sigmas agree and 5 sigma cuts 4e-6 of the corners. The floor
  // keeps a very good fit (renders: 0.02 px) from throwing good corners away. With
  // outlier_bulk_sigmas >= outlier_sigmas the bulk reaches past the cut where the
  // residuals are near-Gaussian (the two sigmas then agree), so the corners the fit keeps
  // count in the sigma that judges them; where the floor sets the cut it may not.
  double outlier_floor_px = 0.5;
  double outlier_sigmas = 5.0;
  double outlier_bulk_sigmas = 8.0;
  // A view whose inlier RMS exceeds max(outlier_floor_px, view_rms_ratio x the median of
  // the views' RMS) is left out (robust mode): it shows something else than the other
  // views' board. Real views differ by up to 2.5x (measured on the dev set).
  double view_rms_ratio = 4.0;
  // Per-view noise weights (variance components): after the robust fit each view's corner
  // noise sigma_v is estimated from its own residuals (its pose's 6 degrees of freedom
  // taken off), its corners weighted by sigma / sigma_v (sigma pooled over all views), and
  // the fit repeated, twice. Views differ several-fold in corner noise (rendered rim views
  // ~5x the inner ones; the real dev set's 0.18-0.46 px RMS): unweighted, the noisy ones
  // pull the sensor as hard as sharp ones and the covariance, scaled by one pooled sigma,
  // misstates both. The weights are clamped to [kMinViewWeight, kMaxViewWeight]; a view
  // with under 20 degrees of freedom (13 corners) keeps weight 1. The robust loss then
  // acts on the weighted residuals: its scale is in px of a unit-weight corner.
  bool view_noise_weights = false;
  // Design tolerances: one standard deviation of a Gaussian prior around the guess's value,
  // per parameter name as FitResult names them (fx_px, cx_px, k1, m_mm, decenter_x_mm,
  // A_mm, ...) or a pair: tilt_deg, decenter_mm, principal_point_px, focal_px. They pull
  // the fit towards the design (a weak prior residual: the wrong basins of the camera
  // rotation / decenter / distortion valley lie many tolerances away) and enter the
  // covariance. A tolerance on a held parameter is ignored (FitResult::tolerance_notes
  // says so); on a sphere with its tilt held, a tilt tolerance widens the decenter's.
  std::map<std::string, double> tolerances;
  // The design values the tolerances are centred on, by parameter name (reported units);
  // a parameter not named here is centred on the guess's value. A pipeline that fits
  // several times (a second detection pass from the first fit) keeps the user's design.
  std::map<std::string, double> design;
  // The board's out-of-plane warp (calib/board_warp.h): fitted with the sensor when
  // fit_board_warp, else held at board_warp (zero: a flat board).
  bool fit_board_warp = false;
  // The board's relief (BoardWarp::relief_mm) fitted too, each corner's offset under a
  // Gaussian prior of kBoardReliefStdMm (it also settles the relief's gauge: a plane of
  // offsets is a tilt of the board every pose takes up). Needs fit_board_warp.
  bool fit_board_relief = false;
  BoardWarp board_warp;
  // Stage "fit", one step per solver iteration; returning false cancels (Cancelled).
  ProgressCallback progress;

  // The gauge-fixing defaults for a sensor, from the registry's traits: an orthographic
  // lens holds m, decenter and its scale; a profile whose tilt is not observable (a
  // sphere: TiltObservable()) holds the tilt; free-form shape terms with a pinhole hold the
  // distortion; a pinhole's tangential terms are held (they trade with decenter and the
  // principal point).
  static FitOptions DefaultsFor(const Sensor& sensor);
  // Empty if valid, else "field: problem".
  std::string Check() const;
  // Check() and the tolerance names against the sensor's parameters ("tolerances.x: ...").
  std::string CheckFor(const Sensor& sensor) const;
};

}  // namespace omnical
