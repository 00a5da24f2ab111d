#include "calib/bundle_fit.h"

#include <ceres/ceres.h>

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <stdexcept>
#include <type_traits>

#include "calib/board_relief_gauge.h"
#include "calib/fit_covariance.h"
#include "calib/parallel_evaluation.h"
#include "calib/reprojection_cost.h"
#include "calib/sensor_blocks.h"
#include "calib/shape_smoothness.h"
#include "calib/view_weighted_cost.h"
#include "model/ceres_progress.h"
#include "model/input_error.h"
#include "model/spline_profile.h"

namespace omnical {
namespace {

constexpr double kDeg = 180.0 / M_PI;

// A parameter this many tolerances from its design is reported (3: a 0.3 % event).
constexpr double kToleranceConflict = 3.0;

// Fewer views than this cannot separate the sensor from the poses (the CLI asks as many).
// With the sensor held (held-out views, calib/cross_validation.h) one view is enough.
constexpr size_t kMinViews = 3;

// A view's corners fewer than this leave its pose (6 unknowns) barely determined.
constexpr size_t kMinCornersPerView = 4;

// FitOptions::view_noise_weights: a view whose residuals leave fewer degrees of freedom
// keeps the pooled noise (weight 1). From 2 of them (4 corners) 1 / sigma^2 has no finite
// mean: the clamp alone would decide its weight.
constexpr int kMinViewFreedom = 20;

// A design tolerance as a residual: noise_px x (x - design) / tolerance. Scaled by the
// corner noise so that, next to residuals in px, it weighs as a Gaussian prior of that
// standard deviation would: with J_prior = noise / tolerance, J^T J / noise^2 gains
// 1 / tolerance^2. The noise is the fit's current estimate (updated between solves).
class PriorCost : public ceres::CostFunction {
 public:
  PriorCost(int block_size, int index, double design, double tolerance, const double* noise_px)
      : index_(index), design_(design), tolerance_(tolerance), noise_px_(noise_px) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(block_size);
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double weight = *noise_px_ / tolerance_;
    residuals[0] = weight * (parameters[0][index_] - design_);
    if (jacobians && jacobians[0]) {
      std::fill(jacobians[0], jacobians[0] + parameter_block_sizes()[0], 0.0);
      jacobians[0][index_] = weight;
    }
    return true;
  }

 private:
  int index_;
  double design_, tolerance_;
  const double* noise_px_;
};

// The parameter names a tolerance key stands for (a pair for the two-component ones).
std::vector<std::string> ToleranceTargets(const std::string& key) {
  if (key == "tilt_deg") return {"tilt_x_deg", "tilt_y_deg"};
  if (key == "decenter_mm") return {"decenter_x_mm", "decenter_y_mm"};
  if (key == "principal_point_px") return {"cx_px", "cy_px"};
  if (key == "focal_px") return {"fx_px", "fy_px"};
  return {key};
}

std::string FormatNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}
std::string FormatPx(double value) { return FormatNumber(value) + " px"; }

// A robust sigma per coordinate: |e| of a 2-D Gaussian has median 1.1774 sigma.
double RobustSigma(std::vector<double> norms) {
  norms.erase(std::remove_if(norms.begin(), norms.end(), [](double n) { return !std::isfinite(n); }), norms.end());
  if (norms.empty()) return 1.0;
  std::nth_element(norms.begin(), norms.begin() + norms.size() / 2, norms.end());
  return norms[norms.size() / 2] / 1.1774;
}

// The sigma per coordinate of the residuals' bulk: sqrt(mean |e|^2 / 2) over the norms
// within bulk_sigmas x RobustSigma (FitOptions::outlier_bulk_sigmas says why).
double BulkSigma(const std::vector<double>& norms, double bulk_sigmas) {
  const double limit = bulk_sigmas * RobustSigma(norms);
  double square_sum = 0.0;
  int count = 0;
  for (double n : norms)
    if (n <= limit) square_sum += n * n, ++count;
  return count > 0 ? std::sqrt(square_sum / (2.0 * count)) : 1.0;
}

// The widest rim in [valid_mm, invalid_mm) that keeps `model` a valid sensor (valid at
// valid_mm, not at invalid_mm): 1 % inside the limit, where the rays graze the mirror, its
// shape stops being convex or the lens's distortion folds; never below valid_mm. Every
// rim-dependent check fails for good once it fails (model/sensor_validation.cc), so a
// bisection finds the limit.
template <typename Model>
double WidestValidRimMm(Model model, double valid_mm, double invalid_mm) {
  const double floor_mm = valid_mm;
  for (int step = 0; step < 30; ++step) {  // to ~1e-9 of the span
    model.rim_radius_mm = 0.5 * (valid_mm + invalid_mm);
    (ValidateSensorModel(model).empty() ? valid_mm : invalid_mm) = model.rim_radius_mm;
  }
  // Checked once more: a failure in a band narrower than the checks' radial sampling could
  // make the bisection's assumption fail.
  model.rim_radius_mm = std::max(floor_mm, 0.99 * valid_mm);
  return ValidateSensorModel(model).empty() ? model.rim_radius_mm : floor_mm;
}

// One fit of one model type: the problem, its stages, and the result it fills.
template <typename Model>
class FitRun {
 public:
  using Cost = typename ReprojectionCostOf<Model>::type;

  FitRun(const Model& guess, const CalibrationTarget& target, const DetectionSet& detections,
         const std::vector<TargetPose>& initial_poses, const FitOptions& options)
      : guess_(guess), detections_(detections), options_(options), blocks_(guess), views_(detections.images.size()),
        evaluation_(options.threads), problem_(ProblemOptions(options.threads > 1 ? &evaluation_ : nullptr)), progress_(options.progress, "fit", 0), iteration_progress_(&progress_) {
    with_warp_ = options.fit_board_warp || !options.board_warp.IsZero();
    warp_mm_ = {options.board_warp.x_mm, options.board_warp.y_mm};
    with_relief_ = options.fit_board_relief || !options.board_warp.relief_mm.empty();
    result_.guess_rim_radius_mm = guess.rim_radius_mm;
    rotations_.resize(views_);
    translations_.resize(views_);
    view_weight_.assign(views_, 1.0);  // never resized after: the costs point into it
    for (size_t v = 0; v < views_; ++v) {
      const Eigen::Quaterniond& q = initial_poses[v].camera_from_target_rotation;
      rotations_[v] = {q.x(), q.y(), q.z(), q.w()};
      for (int k = 0; k < 3; ++k) translations_[v][k] = initial_poses[v].camera_from_target_translation_mm[k];
    }
    for (const TargetCorner& c : target.corners()) corner_points_[c.id] = c.point_in_target;
    if (with_warp_) warp_basis_ = BoardWarp::Basis(target);
    if (with_relief_)
      for (const TargetCorner& c : target.corners()) {
        const auto given = options.board_warp.relief_mm.find(c.id);
        relief_mm_[c.id] = given == options.board_warp.relief_mm.end() ? 0.0 : given->second;
      }
    // Robust mode: a redescending Cauchy loss while far from the solution (gross outliers
    // get almost no weight, where Huber's linear influence would still pull), then the
    // outliers are removed and the last solve uses Huber. The wrapper swaps every loss.
    if (options.robust_loss_px > 0.0)
      loss_ = std::make_unique<ceres::LossFunctionWrapper>(new ceres::CauchyLoss(options.robust_loss_px), ceres::TAKE_OWNERSHIP);
    solver_ = options.solver;
    solver_.callbacks.push_back(&iteration_progress_);
  }

  FitResult Run() {
    if (!AddObservations()) return std::move(result_);
    AddPriors();
    progress_.ThrowIfCancelled();
    SolvePosesAlone();
    SolveSensorInStages();
    if (options_.robust_loss_px > 0.0 && !RejectOutliersAndRefit()) return std::move(result_);
    WeighViewsByNoise();
    Finish();
    return std::move(result_);
  }

 private:
  struct Residual {
    size_t view, index;
    std::unique_ptr<Cost> functor;  // a copy kept to evaluate plain residuals afterwards
    std::vector<double*> blocks;
    ceres::ResidualBlockId id;
    bool outlier = false;
  };
  struct Prior {
    std::string name;
    double* block;
    int index;
    double design, tolerance;  // internal units
    double scale;              // internal -> reported units
  };

  static ceres::Problem::Options ProblemOptions(ceres::EvaluationCallback* evaluation) {
    ceres::Problem::Options problem_options;
    problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_options.evaluation_callback = evaluation;
    return problem_options;
  }

  // A residual block per detected corner that projects through the guess; a view left
  // with too few is left out. False when nothing can be fitted.
  bool AddObservations() {
    result_.residuals_px.resize(views_);
    result_.view_left_out.assign(views_, "");
    result_.per_view_outliers.assign(views_, 0);
    view_residuals_.assign(views_, 0);
    for (size_t v = 0; v < views_; ++v) {
      const ImageDetections& image = detections_.images[v];
      result_.residuals_px[v].assign(image.corners.size(), Eigen::Vector2d::Constant(NAN));
      for (size_t i = 0; i < image.corners.size(); ++i) {
        ++result_.observations;
        const auto point = corner_points_.find(image.corners[i].id);
        if (point == corner_points_.end()) {
          ++result_.dropped;  // an id the target does not have
          continue;
        }
        std::optional<Eigen::Vector2d> basis;
        if (with_warp_) basis = warp_basis_.at(image.corners[i].id);
        auto functor = std::make_unique<Cost>(guess_, point->second, image.corners[i].pixel, basis, with_relief_);
        std::vector<double*> blocks = blocks_.Pointers();
        blocks.push_back(rotations_[v].data());
        blocks.push_back(translations_[v].data());
        if (with_warp_) blocks.push_back(warp_mm_.data());
        if (with_relief_) blocks.push_back(&relief_mm_.at(image.corners[i].id));
        double check[2];
        if (!(*functor)(blocks.data(), check)) {
          ++result_.dropped;  // not projectable at the initial guess
          continue;
        }
        ceres::CostFunction* cost = Cost::Create(guess_, point->second, image.corners[i].pixel, basis, with_relief_);
        if (options_.threads > 1) cost = evaluation_.Wrap(cost, blocks);
        if (options_.view_noise_weights) cost = new ViewWeightedCost(cost, &view_weight_[v]);
        const ceres::ResidualBlockId id = problem_.AddResidualBlock(cost, loss_.get(), blocks);
        residuals_.push_back({v, i, std::move(functor), blocks, id});
        ++view_residuals_[v];
      }
    }
    for (size_t v = 0; v < views_; ++v)
      if (view_residuals_[v] < kMinCornersPerView)
        LeaveOut(v, std::to_string(view_residuals_[v]) + " of " + std::to_string(detections_.images[v].corners.size()) +
                        " corners project through the guess");
    if (std::none_of(residuals_.begin(), residuals_.end(), [](const Residual& r) { return !r.outlier; })) {
      result_.solver_report = "no observation could be projected through the initial guess";
      return false;
    }
    for (size_t v = 0; v < views_; ++v)
      if (problem_.HasParameterBlock(rotations_[v].data()))
        problem_.SetManifold(rotations_[v].data(), new ceres::EigenQuaternionManifold);
    return true;
  }

  // A view is fitted whole or not at all: a pose resting on a few corners is a free gauge
  // that makes every reported std undetermined.
  void LeaveOut(size_t v, const std::string& why) {
    result_.view_left_out[v] = why;
    for (Residual& r : residuals_)
      if (r.view == v) r.outlier = true;
    if (problem_.HasParameterBlock(rotations_[v].data())) problem_.RemoveParameterBlock(rotations_[v].data());
    if (problem_.HasParameterBlock(translations_[v].data())) problem_.RemoveParameterBlock(translations_[v].data());
  }

  // Design tolerances as prior residuals on the sensor's own blocks.
  void AddPriors() {
    std::map<std::string, std::pair<double*, std::pair<int, double>>> named;  // name -> block, index, unit scale
    blocks_.ForEach([&](const ParameterInfo& info, double* block, int index, double scale) {
      named[info.name] = {block, {index, scale}};
    });
    std::map<std::string, double> tolerance_of = ExpandTolerances(options_.tolerances);
    // A sphere's tilt is its gauge (held by default): the fitted decenter is then the
    // offset of its centre, decenter + R (cos tx sin ty, -sin tx) with R the vertex radius
    // of curvature, which the design's tilt error moves too. A tilt tolerance therefore
    // widens the decenter's: sigma_x^2 + (R sigma_ty)^2.
    if (!guess_.mirror.TiltObservable() && !options_.refine.tilt) {
      const double radius_mm = 0.5 / guess_.mirror.template EvaluateSag<double>(0.0).dz_ds;
      for (const auto& [tilt_name, decenter_name] : {std::pair<std::string, std::string>{"tilt_y_deg", "decenter_x_mm"},
                                                     {"tilt_x_deg", "decenter_y_mm"}}) {
        const auto tilt_tolerance = tolerance_of.find(tilt_name);
        if (tilt_tolerance == tolerance_of.end()) continue;
        const double widened = radius_mm * tilt_tolerance->second / kDeg;
        double& decenter_tolerance = tolerance_of[decenter_name];  // 0 if none was given
        decenter_tolerance = std::hypot(decenter_tolerance, widened);
        result_.tolerance_notes.push_back(tilt_name + "'s tolerance widens " + decenter_name + "'s to " +
                                          FormatNumber(decenter_tolerance) +
                                          " mm (a sphere's tilt is held: its centre is what the data see)");
        tolerance_of.erase(tilt_tolerance);
      }
    }
    for (const auto& [name, tolerance] : tolerance_of) {
      const auto found = named.find(name);
      if (found == named.end()) continue;  // FitSensor checked the names
      double* block = found->second.first;
      const auto [index, scale] = found->second.second;
      const auto design = options_.design.find(name);
      const double centre = design != options_.design.end() ? design->second / scale : block[index];
      priors_.push_back({name, block, index, centre, tolerance / scale, scale});
      problem_.AddResidualBlock(new PriorCost(blocks_.BlockSize(block), index, centre, tolerance / scale, &prior_noise_px_),
                                nullptr, block);
    }
    if (options_.fit_board_relief)
      for (auto& [id, offset_mm] : relief_mm_)
        if (problem_.HasParameterBlock(&offset_mm)) {
          problem_.AddResidualBlock(new PriorCost(1, 0, 0.0, kBoardReliefStdMm, &prior_noise_px_), nullptr, &offset_mm);
          relief_priors_.push_back(&offset_mm);
        }
    if (options_.fit_board_relief && !relief_priors_.empty()) {
      Eigen::MatrixXd shapes(relief_priors_.size(), 3);
      int row = 0;
      for (auto& [id, offset_mm] : relief_mm_) {
        if (!problem_.HasParameterBlock(&offset_mm)) continue;
        const Eigen::Vector2d& basis = warp_basis_.at(id);
        shapes.row(row++) << 1.0, basis.x(), basis.y();
      }
      relief_gauge_ =
          problem_.AddResidualBlock(new BoardReliefGaugeCost(shapes, &prior_noise_px_), nullptr, relief_priors_);
    }
    using Profile = typename Model::ProfileType;
    if constexpr (kHasShapeSmoothness<Profile>)
      smoothness_ = problem_.AddResidualBlock(ShapeSmoothnessCost<Profile>::Create(guess_.mirror, &prior_noise_px_),
                                              nullptr, blocks_.shape.data());
  }

  // A spline's vertex curvature c1 (its first shape entry), once held for the covariance.
  std::vector<int> HeldShapeEntries() const {
    return vertex_curvature_held_ ? std::vector<int>{0} : std::vector<int>{};
  }

  // Whether a spline's fitted c1 is a near-gauge, to be held at its fitted value for the
  // covariance. No view sees the axis (the centre shows the camera), and past the first two
  // knot spacings the knots reproduce any line in s = r^2 (B-splines do), c1 s among them,
  // so only corners inside those spacings tell c1 from the knots. Where few do, the
  // covariance of that valley is near-singular and what it predicts is not what the views
  // show: on the OCamCalib KaidanOmni set (no guess, orthographic, 16 knots) c1's std was
  // 19 %, the knots' grew linearly to 3.8 mm, and the predicted error read 4.3 px worst
  // (0.6 median) at the boards' distance, where the corners fit to 0.19 px and held-out
  // folds to 0.21; with c1 held the knots' stds are 0.035 mm and the prediction 0.14 px
  // worst. So: c1 weakly determined (its std beyond kWeakRelativeStd of its value) while,
  // given the knots, known within kWeakRelativeStd (the conditional std, a Schur
  // complement): the knots are what it trades with. A c1 that trades with the lens scale
  // or the decenter instead keeps its std and its warning. Holding it moves nothing: the
  // fit is at its minimum, c1 at its fitted value.
  // Returns c1's std as a share of its value where it is such a near-gauge, else NaN.
  double VertexCurvatureNearGaugeStdRatio(const std::map<const double*, std::vector<int>>& columns,
                                          const Eigen::MatrixXd& covariance) const {
    using Profile = typename Model::ProfileType;
    if constexpr (std::is_same_v<Profile, SplineProfile<double>>) {
      if (!options_.hold_weak_vertex_curvature) return NAN;
      const auto found = columns.find(blocks_.shape.data());
      if (found == columns.end() || found->second.empty() || found->second[0] < 0) return NAN;
      const int c1_column = found->second[0];
      std::vector<int> knot_columns;
      for (size_t k = 1; k < found->second.size(); ++k)
        if (found->second[k] >= 0) knot_columns.push_back(found->second[k]);
      const double c1 = std::abs(blocks_.shape[0]), variance = covariance(c1_column, c1_column);
      if (knot_columns.empty() || !(c1 > 0.0) || !(variance > std::pow(kWeakRelativeStd * c1, 2))) return NAN;
      const int n = static_cast<int>(knot_columns.size());
      Eigen::MatrixXd knots(n, n);
      Eigen::VectorXd with_c1(n);
      for (int i = 0; i < n; ++i) {
        with_c1(i) = covariance(knot_columns[i], c1_column);
        for (int j = 0; j < n; ++j) knots(i, j) = covariance(knot_columns[i], knot_columns[j]);
      }
      // The knots' own covariance may hold a further near-gauge (a constant offset): a
      // pseudo-inverse, not a Cholesky.
      const double given_knots = variance - with_c1.dot(knots.completeOrthogonalDecomposition().solve(with_c1));
      return given_knots < std::pow(kWeakRelativeStd * c1, 2) ? std::sqrt(variance) / c1 : NAN;
    }
    return NAN;
  }

  // The lens entries held throughout (by the refine switches), and in stage 1 also the
  // radial distortion, which otherwise absorbs the error of a poor start and leads into a
  // local minimum. Not the tangential terms: held in stage 1, a start without them (p1 =
  // p2 = 0) put their image shift into the mirror's decenter (15 mm for p1 = 0.016 on the
  // misaligned pinhole sphere), a basin stage 2 did not leave (p1 20 std off); free from
  // the start they were recovered within 1.3 std (tests/calibrate_api_test.cc).
  std::vector<int> HeldLensEntries(bool hold_distortion) const {
    std::vector<int> held;
    for (ParameterGroup group : {ParameterGroup::kFocal, ParameterGroup::kPrincipalPoint, ParameterGroup::kDistortion,
                                 ParameterGroup::kTangential})
      if (!options_.refine.Refines(group) || (hold_distortion && group == ParameterGroup::kDistortion))
        for (int k : SensorBlocks<Model>::LensIndices(group)) held.push_back(k);
    std::sort(held.begin(), held.end());
    return held;
  }
  // Whether stage 1 differs from stage 2: the lens has a distortion the fit may move.
  bool StagedDistortion() const {
    return options_.refine.distortion && !SensorBlocks<Model>::LensIndices(ParameterGroup::kDistortion).empty();
  }

  void SetLens(bool hold_distortion) {
    double* lens = blocks_.lens.data();
    const std::vector<int> held = HeldLensEntries(hold_distortion);
    if (held.size() == blocks_.lens.size()) {
      problem_.SetParameterBlockConstant(lens);
      return;
    }
    problem_.SetParameterBlockVariable(lens);
    problem_.SetManifold(lens, held.empty() ? nullptr : new ceres::SubsetManifold(static_cast<int>(blocks_.lens.size()), held));
  }
  void SetSensor(bool variable) {
    auto toggle = [&](double* block, bool refine) {
      if (variable && refine) {
        problem_.SetParameterBlockVariable(block);
      } else {
        problem_.SetParameterBlockConstant(block);
      }
    };
    toggle(&blocks_.m_mm, options_.refine.m);
    toggle(blocks_.tilt_rad, options_.refine.tilt);
    toggle(blocks_.decenter_mm, options_.refine.decenter);
    if (!blocks_.shape.empty()) toggle(blocks_.shape.data(), options_.refine.shape);
    if (with_warp_ && problem_.HasParameterBlock(warp_mm_.data())) toggle(warp_mm_.data(), options_.fit_board_warp);
    for (auto& [id, offset_mm] : relief_mm_)
      if (problem_.HasParameterBlock(&offset_mm)) toggle(&offset_mm, options_.fit_board_relief);
  }
  void SetPoses(bool variable) {
    for (size_t v = 0; v < views_; ++v) {
      if (!problem_.HasParameterBlock(rotations_[v].data())) continue;
      if (variable && options_.refine.poses) {
        problem_.SetParameterBlockVariable(rotations_[v].data());
        problem_.SetParameterBlockVariable(translations_[v].data());
      } else {
        problem_.SetParameterBlockConstant(rotations_[v].data());
        problem_.SetParameterBlockConstant(translations_[v].data());
      }
    }
  }

  // |residual| of every fitted corner at the current parameters (NaN if it cannot project).
  std::vector<double> ResidualNorms() const {
    std::vector<double> norms(residuals_.size(), NAN);
    for (size_t k = 0; k < residuals_.size(); ++k) {
      double value[2];
      if (!residuals_[k].outlier && (*residuals_[k].functor)(residuals_[k].blocks.data(), value))
        norms[k] = std::hypot(value[0], value[1]);
    }
    return norms;
  }

  // Every stage but the last is only a start for the next one, so it stops once an
  // iteration improves the cost by less than 1e-4 of it (or at the fit's tolerances, if
  // looser); the last runs to the fit's own, near machine precision (Finish). Through a
  // poor guess the residuals stay large and Gauss-Newton converges only linearly: at the
  // fit's tolerances the poses-alone stage ran to its 200 iterations, ~80 % of a fit's
  // time, for a cost change below 1e-5; at Ceres' default 1e-6 the robust stages on the
  // detected renders of tests/bench/omnidir_compare still spent 15-18 iterations each
  // polishing a minimum the next stage moves (1e-4: 3 each, the fit 2.4x faster, the same
  // final cost to 7 digits on the exact and the real rows).
  // Each stage starts from the trust region the one before ended with (Ceres' default
  // radius at the first): in the fit's weakly observable directions (the mirror's distance
  // against its shape and the lens scale) the step is bounded by the radius, and each stage
  // begun at the default spent its first ~8 iterations growing it, 3x per iteration.
  enum class Precision { kStart, kFinal };
  static constexpr double kStartFunctionTolerance = 1e-4;
  void Solve(Precision precision) {
    ceres::Solver::Options options = solver_;
    if (!summary_.iterations.empty())
      options.initial_trust_region_radius =
          std::max(solver_.initial_trust_region_radius, summary_.iterations.back().trust_region_radius);
    if (precision == Precision::kStart) {
      const ceres::Solver::Options defaults;
      options.function_tolerance = std::max(solver_.function_tolerance, kStartFunctionTolerance);
      options.gradient_tolerance = std::max(solver_.gradient_tolerance, defaults.gradient_tolerance);
      options.parameter_tolerance = std::max(solver_.parameter_tolerance, defaults.parameter_tolerance);
    }
    if (options_.threads > 1) evaluation_.UpdateConstantBlocks(problem_);
    ceres::Solve(options, &problem_, &summary_);
    progress_.ThrowIfCancelled();
  }

  // Stage 0: the poses alone, through the guessed sensor.
  void SolvePosesAlone() {
    if (!options_.refine.poses) return;
    problem_.SetParameterBlockConstant(blocks_.lens.data());
    SetSensor(false);
    SetPoses(true);
    Solve(Precision::kStart);
  }

  // Stage 1: everything but the distortion; stage 2: everything asked for. The priors
  // weigh against the residuals left by the stage before (while the start is poor they are
  // large and so hold the sensor near its design: a continuation away from wrong basins).
  void SolveSensorInStages() {
    prior_noise_px_ = std::max(1e-3, RobustSigma(ResidualNorms()));
    SetPoses(true);
    SetSensor(true);
    if (StagedDistortion()) {
      SetLens(true);
      Solve(Precision::kStart);
      prior_noise_px_ = std::max(1e-3, RobustSigma(ResidualNorms()));
    }
    SetLens(false);
    Solve(Precision::kStart);
  }

  // Gross outliers (robust mode): beyond max(floor, k sigma) of the bulk's sigma, removed,
  // then views that fit far worse than the others, and the fit repeated without them under
  // Huber. False when too few views are left.
  bool RejectOutliersAndRefit() {
    const std::vector<double> norms = ResidualNorms();
    const double threshold =
        std::max(options_.outlier_floor_px, options_.outlier_sigmas * BulkSigma(norms, options_.outlier_bulk_sigmas));
    result_.outlier_threshold_px = threshold;
    std::vector<size_t> view_inliers(views_, 0);
    for (size_t k = 0; k < residuals_.size(); ++k) {
      Residual& r = residuals_[k];
      if (r.outlier) continue;
      if (!(norms[k] <= threshold)) {
        r.outlier = true;
        ++result_.outliers;
        ++result_.per_view_outliers[r.view];
        problem_.RemoveResidualBlock(r.id);
      } else {
        ++view_inliers[r.view];
      }
    }
    for (size_t v = 0; v < views_; ++v)
      if (result_.view_left_out[v].empty() && view_inliers[v] < kMinCornersPerView)
        LeaveOut(v, std::to_string(result_.per_view_outliers[v]) + " of " + std::to_string(view_residuals_[v]) +
                        " corners rejected as outliers (beyond " + FormatPx(threshold) + ")");
    // A view that fits as a whole far worse than the others shows something else than
    // their board (a false or a bent board, a wrong size): its corners are not outliers one
    // by one, but together they pull the sensor.
    std::vector<double> view_square(views_, 0.0), view_rms;
    for (size_t k = 0; k < residuals_.size(); ++k)
      if (!residuals_[k].outlier && std::isfinite(norms[k])) view_square[residuals_[k].view] += norms[k] * norms[k];
    for (size_t v = 0; v < views_; ++v)
      if (result_.view_left_out[v].empty()) view_rms.push_back(std::sqrt(view_square[v] / view_inliers[v]));
    if (view_rms.size() >= 3) {
      std::vector<double> sorted = view_rms;
      std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
      const double median_rms = sorted[sorted.size() / 2];
      const double limit = std::max(options_.outlier_floor_px, options_.view_rms_ratio * median_rms);
      for (size_t v = 0, k = 0; v < views_; ++v) {
        if (!result_.view_left_out[v].empty()) continue;
        const double rms = view_rms[k++];
        if (rms > limit)
          LeaveOut(v, "its corners fit at " + FormatPx(rms) + " RMS, beyond " + FormatPx(limit) + " (" +
                          FormatNumber(options_.view_rms_ratio) + " x the views' median " + FormatPx(median_rms) +
                          "): not the board the other views show (a false, bent or wrongly sized board)");
      }
    }
    const size_t fitted_views = std::count(result_.view_left_out.begin(), result_.view_left_out.end(), "");
    if (fitted_views < (options_.refine.RefinesSensor() ? kMinViews : 1)) {
      result_.solver_report = std::to_string(fitted_views) + " views are left after the outlier rule (" +
                              std::to_string(kMinViews) + " needed): the corners do not show one board through one sensor";
      return false;
    }
    loss_->Reset(new ceres::HuberLoss(options_.robust_loss_px), ceres::TAKE_OWNERSHIP);
    prior_noise_px_ = std::max(1e-3, RobustSigma(ResidualNorms()));
    Solve(Precision::kStart);
    return true;
  }

  // Plain residuals at the solution over the inliers; the free blocks; sigma per
  // coordinate with the fit's degrees of freedom (what the covariance is scaled by).
  double Statistics() {
    sum_square_ = 0.0;
    double weighted_square = 0.0;
    inliers_ = 0;
    for (const Residual& r : residuals_) {
      double value[2];
      if (r.outlier || !(*r.functor)(r.blocks.data(), value)) continue;
      const double square = value[0] * value[0] + value[1] * value[1];
      sum_square_ += square;
      weighted_square += square * view_weight_[r.view] * view_weight_[r.view];
      ++inliers_;
    }
    std::vector<double*> all;
    problem_.GetParameterBlocks(&all);
    variable_.clear();
    free_columns_ = 0;
    for (double* b : all)
      if (!problem_.IsParameterBlockConstant(b)) variable_.push_back(b), free_columns_ += problem_.ParameterBlockTangentSize(b);
    // Unit-weight sigma: the weighted residuals' (the covariance's Jacobian is weighted too).
    return std::sqrt(weighted_square / std::max(1, 2 * inliers_ - free_columns_));
  }

  // FitOptions::view_noise_weights: each view's noise from its own inlier residuals (its
  // 2 n - 6 degrees of freedom), weights sigma_pooled / sigma_v, the fit repeated; twice,
  // since each refit moves the residuals the weights came from (a third changed the
  // realistic sets' weights by under 1 %).
  void WeighViewsByNoise() {
    if (!options_.view_noise_weights || !options_.refine.RefinesSensor()) return;
    for (int round = 0; round < 2; ++round) {
      std::vector<double> square_px2(views_, 0.0);
      std::vector<int> count(views_, 0);
      for (const Residual& r : residuals_) {
        double value[2];
        if (r.outlier || !result_.view_left_out[r.view].empty() || !(*r.functor)(r.blocks.data(), value)) continue;
        square_px2[r.view] += value[0] * value[0] + value[1] * value[1];
        ++count[r.view];
      }
      double pooled_square_px2 = 0.0;
      int pooled_freedom = 0;
      for (size_t v = 0; v < views_; ++v)
        if (2 * count[v] > 6) pooled_square_px2 += square_px2[v], pooled_freedom += 2 * count[v] - 6;
      if (pooled_freedom == 0 || !(pooled_square_px2 > 0.0)) break;
      const double pooled_px = std::sqrt(pooled_square_px2 / pooled_freedom);
      for (size_t v = 0; v < views_; ++v) {
        const int freedom = 2 * count[v] - 6;
        const double sigma_px = freedom >= kMinViewFreedom ? std::sqrt(square_px2[v] / freedom) : pooled_px;
        view_weight_[v] =
            sigma_px > 0.0 ? std::clamp(pooled_px / sigma_px, kMinViewWeight, kMaxViewWeight) : kMaxViewWeight;
      }
      prior_noise_px_ = std::max(1e-3, pooled_px);
      Solve(Precision::kStart);
    }
    // Reported as applied (whatever round stopped); a left-out view had none.
    result_.per_view_weight = view_weight_;
    for (size_t v = 0; v < views_; ++v)
      if (!result_.view_left_out[v].empty()) result_.per_view_weight[v] = NAN;
  }

  // The last stage, to the fit's own tolerances.
  void Finish() {
    HoldUnseenRelief();
    result_.sigma_px = Statistics();
    // The priors' final weight: the noise the covariance is scaled by (so the two agree).
    if ((!priors_.empty() || smoothness_ || !relief_priors_.empty()) &&
        std::abs(result_.sigma_px - prior_noise_px_) > 0.05 * prior_noise_px_)
      prior_noise_px_ = std::max(1e-6, result_.sigma_px);
    Solve(Precision::kFinal);
    result_.sigma_px = Statistics();
    result_.converged = summary_.termination_type == ceres::CONVERGENCE;
    result_.solver_report = summary_.BriefReport();
    result_.residual_blocks = problem_.NumResidualBlocks();
    result_.free_parameter_blocks = static_cast<int>(variable_.size());
    result_.free_columns = free_columns_;
    ReportToleranceConflicts();
    ReportResiduals();
    std::map<const double*, std::vector<int>> columns = Columns();
    Eigen::MatrixXd covariance;
    if (options_.compute_covariance) result_.covariance_ok = Covariance(columns, &covariance);
    if (result_.covariance_ok)
      result_.vertex_curvature_std_ratio = VertexCurvatureNearGaugeStdRatio(columns, covariance);
    if (std::isfinite(result_.vertex_curvature_std_ratio)) {
      vertex_curvature_held_ = true;
      problem_.SetManifold(blocks_.shape.data(),
                           new ceres::SubsetManifold(static_cast<int>(blocks_.shape.size()), HeldShapeEntries()));
      columns = Columns(false);
      result_.covariance_ok = Covariance(columns, &covariance);
    }
    ReportParameters(columns, covariance);
    if (options_.fit_board_warp) ReportBoardWarp(columns, covariance);
    result_.sensor = Sensor(FittedModel());
    for (size_t v = 0; v < views_; ++v) {
      TargetPose pose;
      pose.camera_from_target_rotation = Eigen::Quaterniond(rotations_[v][3], rotations_[v][0], rotations_[v][1], rotations_[v][2]);
      pose.camera_from_target_translation_mm = Eigen::Vector3d(translations_[v][0], translations_[v][1], translations_[v][2]);
      result_.poses.push_back(pose);
    }
  }

  // A corner whose every observation was cut as an outlier or left out with its view keeps
  // only its prior: held (at 0, where the prior pulled it) rather than reported as fitted.
  void HoldUnseenRelief() {
    if (relief_priors_.empty()) return;
    std::map<int, int> seen;
    for (const Residual& r : residuals_)
      if (!r.outlier && result_.view_left_out[r.view].empty()) ++seen[detections_.images[r.view].corners[r.index].id];
    for (auto& [id, offset_mm] : relief_mm_)
      if (problem_.HasParameterBlock(&offset_mm) && !problem_.IsParameterBlockConstant(&offset_mm) && seen[id] == 0) {
        problem_.SetParameterBlockConstant(&offset_mm);
        relief_unseen_.insert(id);
      }
  }

  // A parameter that ends many tolerances from its design: the guess, the tolerance or the
  // data is wrong (a prior that strong against the data is no longer a weak one).
  void ReportToleranceConflicts() {
    for (const Prior& prior : priors_) {
      if (problem_.IsParameterBlockConstant(prior.block)) continue;  // held: noted with the columns
      const double moved = std::abs(prior.block[prior.index] - prior.design) / prior.tolerance;
      if (moved > kToleranceConflict)
        result_.tolerance_conflicts.push_back(prior.name + " ended " + FormatNumber(moved) + " tolerances (" +
                                              FormatNumber(prior.tolerance * prior.scale) + ") from its design value " +
                                              FormatNumber(prior.design * prior.scale) +
                                              ": the guess, its tolerance or the data is off");
    }
  }

  void ReportResiduals() {
    std::vector<double> view_sum(views_, 0.0);
    std::vector<int> view_count(views_, 0);
    for (const Residual& r : residuals_) {
      double value[2] = {NAN, NAN};
      // A left-out view has no fitted pose: its corners stay NaN ("dropped" in reports).
      if (!result_.view_left_out[r.view].empty() || !(*r.functor)(r.blocks.data(), value)) continue;
      const Eigen::Vector2d e(value[0], value[1]);
      result_.residuals_px[r.view][r.index] = e;
      if (r.outlier) continue;
      view_sum[r.view] += e.squaredNorm();
      ++view_count[r.view];
    }
    result_.rms_px = std::sqrt(sum_square_ / std::max(1, inliers_));
    for (size_t v = 0; v < views_; ++v)
      result_.per_view_rms_px.push_back(view_count[v] ? std::sqrt(view_sum[v] / view_count[v]) : NAN);
  }

  // The covariance column of each entry of each free block (-1 where an entry is held by
  // the block's SubsetManifold), in the order Ceres evaluates the free blocks.
  std::map<const double*, std::vector<int>> Columns(bool note_unused_tolerances = true) {
    std::map<const double*, std::vector<int>> columns;
    const std::vector<int> held_lens = HeldLensEntries(false);
    int column = 0;
    for (double* b : variable_) {
      const int tangent = problem_.ParameterBlockTangentSize(b), size = problem_.ParameterBlockSize(b);
      std::vector<int> map(size, -1);
      const bool lens_or_shape = b == blocks_.lens.data() || b == blocks_.shape.data();
      if (lens_or_shape && tangent < size) {  // held entries of the lens or the shape: the free ones in order
        const std::vector<int> held = b == blocks_.lens.data() ? held_lens : HeldShapeEntries();
        int t = 0;
        for (int k = 0; k < size; ++k)
          if (std::find(held.begin(), held.end(), k) == held.end()) map[k] = column + t++;
      } else if (tangent == size) {
        for (int k = 0; k < size; ++k) map[k] = column + k;
      }
      columns[b] = map;
      column += tangent;
    }
    for (const Prior& prior : priors_) {
      const auto found = columns.find(prior.block);
      if (note_unused_tolerances && (found == columns.end() || found->second[prior.index] < 0))
        result_.tolerance_notes.push_back("the tolerance on " + prior.name + " is not used: the parameter is held");
    }
    return columns;
  }

  bool Covariance(const std::map<const double*, std::vector<int>>& columns, Eigen::MatrixXd* covariance) {
    std::vector<ceres::ResidualBlockId> data_blocks;
    for (const Residual& r : residuals_)
      if (!r.outlier) data_blocks.push_back(r.id);
    // The smoothness prior weighs by the corner noise, as the data do: scaled by 1 / sigma
    // with them it enters as the Gaussian prior it stands for.
    if (smoothness_ && options_.refine.shape) data_blocks.push_back(smoothness_);
    if (relief_gauge_) data_blocks.push_back(relief_gauge_);  // weighted by the noise as the smoothness is
    std::vector<PriorRow> prior_rows;
    for (const Prior& prior : priors_) {
      const auto found = columns.find(prior.block);
      if (found != columns.end() && found->second[prior.index] >= 0)
        prior_rows.push_back({found->second[prior.index], 1.0 / prior.tolerance});
    }
    for (const double* offset_mm : relief_priors_) {
      const auto found = columns.find(offset_mm);
      if (found != columns.end() && found->second[0] >= 0)
        prior_rows.push_back({found->second[0], 1.0 / kBoardReliefStdMm});
    }
    return EstimateCovariance(&problem_, variable_, data_blocks, prior_rows, result_.sigma_px, covariance);
  }

  // Every sensor parameter with its std, and the covariance of the free ones in reported
  // units (rows in the order of covariance_names).
  void ReportParameters(const std::map<const double*, std::vector<int>>& columns, const Eigen::MatrixXd& covariance) {
    std::vector<std::pair<int, double>> rows;  // column, unit scale
    blocks_.ForEach([&](const ParameterInfo& info, double* block, int index, double scale) {
      ParameterEstimate estimate;
      estimate.name = info.name;
      estimate.group = info.group;
      estimate.scale_like = info.scale_like;
      estimate.value = block[index] * scale;
      const auto found = columns.find(block);
      const int column = found == columns.end() ? -1 : found->second[index];
      // A spline's c1 held for the covariance was fitted: free, its std undetermined.
      const bool held_for_covariance = vertex_curvature_held_ && block == blocks_.shape.data() && index == 0;
      estimate.fixed = column < 0 && !held_for_covariance;
      if (result_.covariance_ok && column >= 0) {
        estimate.std = std::sqrt(std::max(0.0, covariance(column, column))) * scale;
        rows.push_back({column, scale});
        result_.covariance_names.push_back(info.name);
      }
      if (!estimate.fixed && (!result_.covariance_ok || held_for_covariance)) estimate.std = NAN;  // undetermined
      result_.parameters.push_back(estimate);
    });
    result_.covariance.resize(rows.size(), rows.size());
    for (size_t i = 0; i < rows.size(); ++i)
      for (size_t j = 0; j < rows.size(); ++j)
        result_.covariance(i, j) = covariance(rows[i].first, rows[j].first) * rows[i].second * rows[j].second;
    result_.correlation = CorrelationOf(result_.covariance);
  }

  void ReportBoardWarp(const std::map<const double*, std::vector<int>>& columns, const Eigen::MatrixXd& covariance) {
    BoardWarpEstimate estimate;
    estimate.warp.x_mm = warp_mm_[0];
    estimate.warp.y_mm = warp_mm_[1];
    const auto found = columns.find(warp_mm_.data());
    if (result_.covariance_ok && found != columns.end() && found->second[0] >= 0 && found->second[1] >= 0) {
      estimate.std_x_mm = std::sqrt(std::max(0.0, covariance(found->second[0], found->second[0])));
      estimate.std_y_mm = std::sqrt(std::max(0.0, covariance(found->second[1], found->second[1])));
    }
    // Only the corners some view fitted: a corner no view saw has no relief to report.
    for (const auto& [id, offset_mm] : relief_mm_) {
      if (!problem_.HasParameterBlock(&offset_mm) || relief_unseen_.count(id)) continue;
      estimate.warp.relief_mm[id] = offset_mm;
      const auto column = columns.find(&offset_mm);
      estimate.relief_std_mm[id] = result_.covariance_ok && column != columns.end() && column->second[0] >= 0
                                       ? std::sqrt(std::max(0.0, covariance(column->second[0], column->second[0])))
                                       : NAN;
    }
    result_.board_warp = estimate;
  }

  // The fitted model. Its rim encloses every corner it was fitted on (the fit lets
  // reflections stray up to 15 % past the guess's rim): remap tables and the image area
  // then cover all calibrated image.
  Model FittedModel() const {
    Model fitted = blocks_.ToModel();
    Model wide = fitted;
    wide.rim_radius_mm = std::min(1.15 * guess_.rim_radius_mm, 0.99 * guess_.mirror.MaxRadiusMm());
    const Eigen::Matrix3d camera_from_mirror = fitted.pose.CameraFromMirrorRotation();
    const Eigen::Vector3d mirror_origin = fitted.pose.CameraFromMirrorTranslation();
    double corners_mm = 0.0;
    for (const Residual& r : residuals_) {
      if (r.outlier) continue;
      const Eigen::Quaterniond rotation(rotations_[r.view][3], rotations_[r.view][0], rotations_[r.view][1], rotations_[r.view][2]);
      const Eigen::Vector3d in_camera = rotation * r.functor->point_in_target_mm() +
                                        Eigen::Vector3d(translations_[r.view][0], translations_[r.view][1], translations_[r.view][2]);
      Eigen::Vector3d mirror_point;
      if (wide.ReflectionPoint(in_camera, &mirror_point) != ProjectionStatus::kOk) continue;
      const Eigen::Vector3d in_mirror = camera_from_mirror.transpose() * (mirror_point - mirror_origin);
      corners_mm = std::max(corners_mm, std::hypot(in_mirror.x(), in_mirror.y()));
    }
    // A hair beyond the widest so that the corner itself projects inside.
    const double enclosing_mm = std::min(corners_mm * (1.0 + 1e-6), 0.99 * fitted.mirror.MaxRadiusMm());
    if (enclosing_mm > fitted.rim_radius_mm) fitted.rim_radius_mm = enclosing_mm;
    // A rim past what the fitted lens can see would be written as a sensor nothing loads. A
    // pinhole's start reaches 1.5 x past the nominal rim (calib/initial_sensor.h) in case
    // the fit grows the mirror; it may shrink it instead (the hyperboloid-800x600 renders,
    // --lens pinhole: the rim left at 30 mm, the mirror seen edge-on from 14.7 mm). Then the
    // rim is drawn in to just inside the widest valid one (where the rays graze the mirror),
    // enclosing the corners still.
    if (fitted.rim_radius_mm > enclosing_mm && !ValidateSensorModel(fitted).empty()) {
      Model trial = fitted;
      trial.rim_radius_mm = enclosing_mm;
      if (ValidateSensorModel(trial).empty())
        fitted.rim_radius_mm = WidestValidRimMm(fitted, enclosing_mm, fitted.rim_radius_mm);
    }
    return fitted;
  }

  const Model& guess_;
  const DetectionSet& detections_;
  const FitOptions& options_;
  SensorBlocks<Model> blocks_;
  size_t views_;
  std::vector<std::array<double, 4>> rotations_;
  std::vector<std::array<double, 3>> translations_;
  std::map<int, Eigen::Vector3d> corner_points_;
  // The board's warp block (calib/board_warp.h): present when fitted or held non-zero.
  bool with_warp_ = false;
  std::array<double, 2> warp_mm_{{0.0, 0.0}};
  // The board's relief (FitOptions::fit_board_relief), one block per corner id: a map's
  // values keep their addresses, which the costs hold.
  bool with_relief_ = false;
  std::map<int, double> relief_mm_;
  std::vector<double*> relief_priors_;             // in relief_mm_'s order, as the gauge's blocks
  ceres::ResidualBlockId relief_gauge_ = nullptr;  // calib/board_relief_gauge.h
  std::set<int> relief_unseen_;                    // ids whose every corner was cut or left out: held, not reported
  std::map<int, Eigen::Vector2d> warp_basis_;
  std::unique_ptr<ceres::LossFunctionWrapper> loss_;
  ParallelEvaluation evaluation_;  // before the problem: its costs forget themselves here
  ceres::Problem problem_;
  std::vector<Residual> residuals_;
  std::vector<size_t> view_residuals_;
  std::vector<double> view_weight_;  // FitOptions::view_noise_weights; 1 otherwise
  std::vector<Prior> priors_;
  ceres::ResidualBlockId smoothness_ = nullptr;  // a free-form profile's (calib/shape_smoothness.h)
  double prior_noise_px_ = 1.0;  // the corner noise the priors are scaled by; updated between solves
  bool vertex_curvature_held_ = false;  // a spline's c1, for the covariance (VertexCurvatureNearGaugeStdRatio)
  ceres::Solver::Options solver_;
  ProgressReporter progress_;
  IterationProgress iteration_progress_;
  ceres::Solver::Summary summary_;
  FitResult result_;
  double sum_square_ = 0.0;
  int inliers_ = 0;
  int free_columns_ = 0;
  std::vector<double*> variable_;
};

// Calls each(info, value pointer, unit scale) for every parameter of a model, through
// copies of its blocks, and returns the model with the copies put back.
template <typename Model, typename Each>
Model WithEachParameter(const Model& model, const Each& each) {
  SensorBlocks<Model> blocks(model);
  blocks.ForEach([&](const ParameterInfo& info, double* block, int index, double scale) { each(info, block + index, scale); });
  return blocks.ToModel();
}

}  // namespace

std::map<std::string, double> ExpandTolerances(const std::map<std::string, double>& tolerances) {
  std::map<std::string, double> expanded;
  for (const auto& [key, tolerance] : tolerances)  // pairs first: a component named on its own wins
    if (ToleranceTargets(key).size() > 1)
      for (const std::string& name : ToleranceTargets(key)) expanded[name] = tolerance;
  for (const auto& [key, tolerance] : tolerances)
    if (ToleranceTargets(key).size() == 1) expanded[key] = tolerance;
  return expanded;
}

std::vector<ParameterEstimate> SensorParameters(const Sensor& sensor) {
  std::vector<ParameterEstimate> parameters;
  std::visit(
      [&](const auto& model) {
        WithEachParameter(model, [&](const ParameterInfo& info, double* value, double scale) {
          ParameterEstimate e;
          e.name = info.name;
          e.group = info.group;
          e.scale_like = info.scale_like;
          e.value = *value * scale;
          parameters.push_back(e);
        });
      },
      sensor.model());
  return parameters;
}

Sensor SensorWithWidestValidRim(const Sensor& sensor, double max_factor) {
  return std::visit(
      [&](auto model) {
        if (!ValidateSensorModel(model).empty()) return Sensor(model);
        const double rim_mm = model.rim_radius_mm;
        const double widest_mm = std::min(max_factor * rim_mm, 0.99 * model.mirror.MaxRadiusMm());
        model.rim_radius_mm = widest_mm;
        if (!ValidateSensorModel(model).empty()) model.rim_radius_mm = WidestValidRimMm(model, rim_mm, widest_mm);
        return Sensor(model);
      },
      sensor.model());
}

Sensor SensorWithWiderRim(const Sensor& sensor, double factor) {
  return std::visit(
      [&](auto model) {
        model.rim_radius_mm = std::min(factor * model.rim_radius_mm, 0.99 * model.mirror.MaxRadiusMm());
        return Sensor(model);
      },
      sensor.model());
}

Sensor SensorWithParameters(const Sensor& sensor, const std::vector<double>& values) {
  return std::visit(
      [&](const auto& model) {
        size_t next = 0;
        const auto changed = WithEachParameter(model, [&](const ParameterInfo&, double* value, double scale) {
          if (next < values.size()) *value = values[next] / scale;
          ++next;
        });
        if (next != values.size())
          throw std::invalid_argument("SensorWithParameters: " + std::to_string(values.size()) + " values for " +
                                      std::to_string(next) + " parameters");
        return Sensor(changed);
      },
      sensor.model());
}

std::string FitOptions::CheckFor(const Sensor& sensor) const {
  if (std::string why = Check(); !why.empty()) return why;
  std::set<std::string> names;
  std::string list;
  for (const ParameterEstimate& p : SensorParameters(sensor)) names.insert(p.name), list += p.name + ", ";
  for (const auto& [name, value] : design)
    if (!names.count(name) || !std::isfinite(value)) return "design." + name + ": not a parameter of this sensor, or not finite";
  for (const auto& [key, tolerance] : tolerances) {
    for (const std::string& name : ToleranceTargets(key))
      if (!names.count(name))
        return "tolerances." + key + ": not a parameter of this " + sensor.profile_name() + " / " + sensor.lens_name() +
               " sensor (" + list + "tilt_deg, decenter_mm, principal_point_px, focal_px)";
    if (!(tolerance > 0.0) || !std::isfinite(tolerance)) return "tolerances." + key + ": must be a positive number";
  }
  return {};
}

bool InitialTargetPose(const Sensor& sensor, const CalibrationTarget& target, const ImageDetections& image,
                       TargetPose* pose) {
  std::map<int, Eigen::Vector3d> corner_points;
  for (const TargetCorner& c : target.corners()) corner_points[c.id] = c.point_in_target;
  std::vector<Eigen::Vector3d> points, origins, directions;
  for (const CornerObservation& observation : image.corners) {
    const auto point = corner_points.find(observation.id);
    Eigen::Vector3d origin, direction;
    if (point == corner_points.end() || sensor.Unproject(observation.pixel, &origin, &direction) != ProjectionStatus::kOk)
      continue;
    points.push_back(point->second);
    origins.push_back(origin);
    directions.push_back(direction);
  }
  if (points.size() < 4) return false;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero(), mean_direction = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < points.size(); ++i) centre += origins[i], mean_direction += directions[i];
  centre /= static_cast<double>(points.size());
  mean_direction.normalize();
  // A virtual pinhole at the rays' mean origin looking along their mean direction.
  const Eigen::Matrix3d virtual_from_camera =
      Eigen::Quaterniond::FromTwoVectors(mean_direction, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> bearing;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d b = virtual_from_camera * directions[i];
    if (b.z() < 0.2) continue;  // beyond ~78 deg from the mean direction
    object.emplace_back(points[i].x(), points[i].y(), points[i].z());
    bearing.emplace_back(b.x() / b.z(), b.y() / b.z());
  }
  if (object.size() < 4) return false;
  cv::Mat rvec, tvec;
  const cv::Mat identity = cv::Mat::eye(3, 3, CV_64F);
  if (!cv::solvePnP(object, bearing, identity, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_IPPE)) return false;
  cv::solvePnP(object, bearing, identity, cv::noArray(), rvec, tvec, true, cv::SOLVEPNP_ITERATIVE);
  cv::Mat rotation_cv;
  cv::Rodrigues(rvec, rotation_cv);
  Eigen::Matrix3d virtual_from_target;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) virtual_from_target(r, c) = rotation_cv.at<double>(r, c);
  const Eigen::Vector3d t(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  pose->camera_from_target_rotation = Eigen::Quaterniond(virtual_from_camera.transpose() * virtual_from_target).normalized();
  pose->camera_from_target_translation_mm = virtual_from_camera.transpose() * t + centre;
  return true;
}

FitResult FitSensor(const Sensor& guess, const CalibrationTarget& target, const DetectionSet& detections,
                    const std::vector<TargetPose>& initial_poses, const FitOptions& options) {
  if (const std::string why = options.CheckFor(guess); !why.empty()) throw InputError(why);
  if (initial_poses.size() != detections.images.size())
    throw std::invalid_argument("FitSensor: one initial pose per view is needed");
  return std::visit([&](const auto& model) { return FitRun(model, target, detections, initial_poses, options).Run(); },
                    guess.model());
}

ceres::CostFunction* CreateReprojectionCost(const SensorModel& model, const Eigen::Vector3d& point_in_target_mm,
                                            const Eigen::Vector2d& observed_px) {
  return std::visit(
      [&](const auto& m) -> ceres::CostFunction* {
        return ReprojectionCostOf<std::decay_t<decltype(m)>>::type::Create(m, point_in_target_mm, observed_px);
      },
      model);
}

}  // namespace omnical
