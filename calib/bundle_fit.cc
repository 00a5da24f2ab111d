#include "calib/bundle_fit.h"
#include "model/ceres_progress.h"

#include "model/input_error.h"

#include <ceres/ceres.h>

#include <Eigen/SVD>

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <stdexcept>

namespace omnical {
namespace {

constexpr double kDeg = 180.0 / M_PI;

template <typename Profile>
constexpr bool kTabulated = std::is_same_v<Profile, TabulatedProfile<double>>;
template <typename Profile>
constexpr bool kPolynomial = std::is_same_v<Profile, EvenPolynomialProfile<double>>;

// Exact non-central reprojection error of one target corner (Ceres cost functor).
// Blocks: lens, m, tilt (2), decenter (2), [shape], rotation (x, y, z, w), translation.
template <template <typename> class Profile, template <typename> class Lens>
struct ReprojectionError {
  const Catadioptric<double, Profile, Lens>* base;  // rim, image size, a tabulated table
  Eigen::Vector3d point_in_target_mm;
  Eigen::Vector2d observed_px;
  int shape_count;

  template <typename T>
  bool operator()(T const* const* p, T* residual) const {
    Catadioptric<T, Profile, Lens> model;
    model.lens = Lens<T>::FromParams(p[0]);
    model.pose = MirrorPose<T>{p[1][0], p[2][0], p[2][1], p[3][0], p[3][1]};
    int next = 4;
    if constexpr (kTabulated<Profile<double>>) {
      model.mirror = base->mirror.template Cast<T>();
    } else if constexpr (kPolynomial<Profile<double>>) {
      model.mirror = Profile<T>::FromParams(p[next++], shape_count);
    } else {
      model.mirror = Profile<T>::FromParams(p[next++]);
    }
    // The corner was detected, so its reflection lies on the mirror; iterates may stray a
    // little past the rim, where the profile is still defined.
    model.rim_radius_mm = std::min(1.15 * base->rim_radius_mm, 0.99 * base->mirror.MaxRadiusMm());
    model.image_width_px = base->image_width_px;
    model.image_height_px = base->image_height_px;
    const Eigen::Quaternion<T> rotation(p[next][3], p[next][0], p[next][1], p[next][2]);
    const Vec3<T> in_camera = rotation * point_in_target_mm.cast<T>() + Vec3<T>(p[next + 1][0], p[next + 1][1], p[next + 1][2]);
    Vec3<T> mirror_point;
    // The corner was detected: no image-bounds or occlusion test, only the optics.
    if (model.ReflectionPoint(in_camera, &mirror_point) != ProjectionStatus::kOk) return false;
    Vec2<T> pixel;
    if (!model.lens.ProjectToPixel(mirror_point, &pixel)) return false;
    residual[0] = pixel(0) - T(observed_px.x());
    residual[1] = pixel(1) - T(observed_px.y());
    return true;
  }
};

// The cost functor of a model type. Deduced from the Catadioptric's own template
// arguments: clang (unlike GCC) treats Model::ProfileOf, an alias template, as a template
// distinct from the profile itself (CWG 1286), and the functor's pointer type then mismatches.
template <typename T, template <typename> class Profile, template <typename> class Lens>
ReprojectionError<Profile, Lens> CostFor(const Catadioptric<T, Profile, Lens>*);

std::vector<std::string> SplitNames(const char* info) {
  std::vector<std::string> names;
  std::stringstream stream(info);
  std::string item;
  while (std::getline(stream, item, ',')) {
    item.erase(0, item.find_first_not_of(' '));
    names.push_back(item.substr(0, item.find(' ')));
  }
  return names;
}

// Calls add(name, block, index, unit scale) for every sensor parameter, in a fixed order.
template <typename LensD, typename ProfileD, typename Pointer, typename Add>
void ForEachParameter(Pointer lens, Pointer m_mm, Pointer tilt, Pointer decenter, Pointer shape, int shape_count,
                      const Add& add) {
  const std::vector<std::string> lens_names = SplitNames(LensD::kParamsInfo);
  for (int k = 0; k < LensD::kNumParams; ++k) add(lens_names[k], lens, k, 1.0);
  add("m_mm", m_mm, 0, 1.0);
  add("tilt_x_deg", tilt, 0, kDeg);
  add("tilt_y_deg", tilt, 1, kDeg);
  add("decenter_x_mm", decenter, 0, 1.0);
  add("decenter_y_mm", decenter, 1, 1.0);
  if constexpr (!kTabulated<ProfileD>) {
    const std::vector<std::string> names = kPolynomial<ProfileD> ? std::vector<std::string>{} : SplitNames(ProfileD::kParamsInfo);
    for (int k = 0; k < shape_count; ++k) add(kPolynomial<ProfileD> ? "c" + std::to_string(k + 1) : names[k], shape, k, 1.0);
  }
}

// The model with its blocks set from the fit's arrays.
template <typename Model>
Model WithBlocks(Model model, const double* lens, double m_mm, const double* tilt, const double* decenter,
                 const double* shape, int shape_count) {
  using ProfileD = typename Model::ProfileType;
  model.lens = Model::LensType::FromParams(lens);
  model.pose = MirrorPose<double>{m_mm, tilt[0], tilt[1], decenter[0], decenter[1]};
  if constexpr (kPolynomial<ProfileD>) {
    model.mirror = ProfileD::FromParams(shape, shape_count);
  } else if constexpr (!kTabulated<ProfileD>) {
    model.mirror = ProfileD::FromParams(shape);
  }
  return model;
}

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

namespace {

// A parameter this many tolerances from its design is reported (3: a 0.3 % event).
constexpr double kToleranceConflict = 3.0;

// Fewer views than this cannot separate the sensor from the poses (the CLI asks as many).
constexpr size_t kMinViews = 3;

// A view's corners fewer than this leave its pose (6 unknowns) barely determined.
constexpr size_t kMinCornersPerView = 4;

template <typename Model>
FitResult FitModel(const Model& guess, const CalibrationTarget& target, const DetectionSet& detections,
                   const std::vector<TargetPose>& initial_poses, const FitOptions& options) {
  using LensD = typename Model::LensType;
  using ProfileD = typename Model::ProfileType;
  using Cost = decltype(CostFor(static_cast<const Model*>(nullptr)));
  FitResult result;
  result.guess_rim_radius_mm = guess.rim_radius_mm;

  std::vector<double> lens(LensD::kNumParams);
  guess.lens.ToParams(lens.data());
  double m_mm = guess.pose.m_mm;
  double tilt[2] = {guess.pose.tilt_x_rad, guess.pose.tilt_y_rad};
  double decenter[2] = {guess.pose.decenter_x_mm, guess.pose.decenter_y_mm};
  std::vector<double> shape;
  int shape_count = 0;
  if constexpr (!kTabulated<ProfileD>) {
    if constexpr (kPolynomial<ProfileD>) {
      shape_count = guess.mirror.NumParams();
    } else {
      shape_count = ProfileD::kNumParams;
    }
    shape.resize(shape_count);
    guess.mirror.ToParams(shape.data());
  }
  const size_t views = detections.images.size();
  std::vector<std::array<double, 4>> rotations(views);
  std::vector<std::array<double, 3>> translations(views);
  for (size_t v = 0; v < views; ++v) {
    const Eigen::Quaterniond& q = initial_poses[v].camera_from_target_rotation;
    rotations[v] = {q.x(), q.y(), q.z(), q.w()};
    for (int k = 0; k < 3; ++k) translations[v][k] = initial_poses[v].camera_from_target_translation_mm[k];
  }

  std::map<int, Eigen::Vector3d> corner_points;
  for (const TargetCorner& c : target.corners()) corner_points[c.id] = c.point_in_target;

  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  // Robust mode: a redescending Cauchy loss while far from the solution (gross outliers get
  // almost no weight, where Huber's linear influence would still pull), then the outliers
  // are removed and the last solve uses Huber. The wrapper swaps the loss of every residual.
  std::unique_ptr<ceres::LossFunctionWrapper> loss;
  if (options.robust_loss_px > 0.0)
    loss = std::make_unique<ceres::LossFunctionWrapper>(new ceres::CauchyLoss(options.robust_loss_px), ceres::TAKE_OWNERSHIP);
  struct Residual {
    size_t view, index;
    std::unique_ptr<Cost> functor;  // a copy kept to evaluate plain residuals afterwards
    std::vector<double*> blocks;
    ceres::ResidualBlockId id;
    bool outlier = false;
  };
  std::vector<Residual> residuals;
  result.residuals_px.resize(views);
  result.view_left_out.assign(views, "");
  result.per_view_outliers.assign(views, 0);
  std::vector<size_t> view_residuals(views, 0);
  for (size_t v = 0; v < views; ++v) {
    const ImageDetections& image = detections.images[v];
    result.residuals_px[v].assign(image.corners.size(), Eigen::Vector2d::Constant(NAN));
    for (size_t i = 0; i < image.corners.size(); ++i) {
      ++result.observations;
      const auto point = corner_points.find(image.corners[i].id);
      if (point == corner_points.end()) {
        ++result.dropped;  // an id the target does not have
        continue;
      }
      const Cost cost_template{&guess, point->second, image.corners[i].pixel, shape_count};
      std::vector<double*> blocks = {lens.data(), &m_mm, tilt, decenter};
      if (!shape.empty()) blocks.push_back(shape.data());
      blocks.push_back(rotations[v].data());
      blocks.push_back(translations[v].data());
      double check[2];
      if (!cost_template(blocks.data(), check)) {
        ++result.dropped;  // not projectable at the initial guess
        continue;
      }
      auto* cost = new ceres::DynamicAutoDiffCostFunction<Cost, 8>(new Cost(cost_template));
      cost->AddParameterBlock(static_cast<int>(lens.size()));
      cost->AddParameterBlock(1);
      cost->AddParameterBlock(2);
      cost->AddParameterBlock(2);
      if (!shape.empty()) cost->AddParameterBlock(static_cast<int>(shape.size()));
      cost->AddParameterBlock(4);
      cost->AddParameterBlock(3);
      cost->SetNumResiduals(2);
      const ceres::ResidualBlockId id = problem.AddResidualBlock(cost, loss.get(), blocks);
      residuals.push_back({v, i, std::make_unique<Cost>(cost_template), blocks, id});
      ++view_residuals[v];
    }
  }
  // A view is fitted whole or not at all: a pose resting on a few corners is a free gauge
  // that makes every reported std undetermined.
  auto leave_out = [&](size_t v, const std::string& why) {
    result.view_left_out[v] = why;
    for (Residual& r : residuals)
      if (r.view == v) r.outlier = true;
    if (problem.HasParameterBlock(rotations[v].data())) problem.RemoveParameterBlock(rotations[v].data());
    if (problem.HasParameterBlock(translations[v].data())) problem.RemoveParameterBlock(translations[v].data());
  };
  for (size_t v = 0; v < views; ++v)
    if (view_residuals[v] < kMinCornersPerView)
      leave_out(v, std::to_string(view_residuals[v]) + " of " + std::to_string(detections.images[v].corners.size()) +
                       " corners project through the guess");
  if (std::none_of(residuals.begin(), residuals.end(), [](const Residual& r) { return !r.outlier; })) {
    result.solver_report = "no observation could be projected through the initial guess";
    return result;
  }
  for (size_t v = 0; v < views; ++v)
    if (problem.HasParameterBlock(rotations[v].data())) problem.SetManifold(rotations[v].data(), new ceres::EigenQuaternionManifold);

  // Design tolerances as prior residuals on the sensor's own blocks.
  struct Prior {
    std::string name;
    double* block;
    int index;
    double design, tolerance;  // internal units
    double scale;              // internal -> reported units
  };
  std::map<std::string, std::pair<double*, std::pair<int, double>>> named;  // name -> block, index, unit scale
  ForEachParameter<LensD, ProfileD>(lens.data(), &m_mm, tilt, decenter, shape.data(), shape_count,
                                    [&](const std::string& name, double* block, int index, double scale) {
                                      named[name] = {block, {index, scale}};
                                    });
  const std::map<const double*, int> block_sizes = {{lens.data(), static_cast<int>(lens.size())}, {&m_mm, 1}, {tilt, 2},
                                                    {decenter, 2}, {shape.data(), static_cast<int>(shape.size())}};
  double prior_noise_px = 1.0;  // the corner noise the priors are scaled by; updated below
  std::map<std::string, double> tolerance_of = ExpandTolerances(options.tolerances);
  // A sphere's tilt is its gauge (held by default): the fitted decenter is then the offset
  // of its centre, decenter + A (cos tx sin ty, -sin tx), which the design's tilt error
  // moves too. A tilt tolerance therefore widens the decenter's: sigma_x^2 + (A sigma_ty)^2.
  if constexpr (std::is_same_v<ProfileD, SphereProfile<double>>) {
    if (options.fixed.count("tilt")) {
      const double radius_mm = guess.mirror.radius_of_curvature_mm;
      for (const auto& [tilt_name, decenter_name] : {std::pair<std::string, std::string>{"tilt_y_deg", "decenter_x_mm"},
                                                     {"tilt_x_deg", "decenter_y_mm"}}) {
        const auto tilt_tolerance = tolerance_of.find(tilt_name);
        if (tilt_tolerance == tolerance_of.end()) continue;
        const double widened = radius_mm * tilt_tolerance->second / kDeg;
        double& decenter_tolerance = tolerance_of[decenter_name];  // 0 if none was given
        decenter_tolerance = std::hypot(decenter_tolerance, widened);
        result.tolerance_notes.push_back(tilt_name + "'s tolerance widens " + decenter_name + "'s to " +
                                         FormatNumber(decenter_tolerance) +
                                         " mm (a sphere's tilt is held: its centre is what the data see)");
        tolerance_of.erase(tilt_tolerance);
      }
    }
  }
  std::vector<Prior> priors;
  for (const auto& [name, tolerance] : tolerance_of) {
    const auto found = named.find(name);
    if (found == named.end()) continue;  // FitSensor checked the names
    double* block = found->second.first;
    const auto [index, scale] = found->second.second;
    const auto design = options.design.find(name);
    const double centre = design != options.design.end() ? design->second / scale : block[index];
    priors.push_back({name, block, index, centre, tolerance / scale, scale});
    problem.AddResidualBlock(new PriorCost(block_sizes.at(block), index, centre, tolerance / scale, &prior_noise_px), nullptr,
                             block);
  }

  // Which lens entries are held: all, the scale (fx, fy or the orthographic scale), and in
  // stage 1 the radial distortion (k1, k2), which otherwise absorbs the error of a poor
  // start and leads into a local minimum.
  const bool lens_fixed = options.fixed.count("lens") > 0;
  std::vector<int> held_scale;
  if (options.fixed.count("lens_scale")) held_scale = LensD::kIsOrthographic ? std::vector<int>{0} : std::vector<int>{0, 1};
  std::vector<int> distortion;
  if constexpr (!LensD::kIsOrthographic) distortion = {4, 5};
  if (options.fixed.count("distortion")) {  // held throughout, like the scale
    held_scale.insert(held_scale.end(), distortion.begin(), distortion.end());
    distortion.clear();
  }
  auto set_lens = [&](bool hold_distortion) {
    if (lens_fixed) {
      problem.SetParameterBlockConstant(lens.data());
      return;
    }
    problem.SetParameterBlockVariable(lens.data());
    std::vector<int> held = held_scale;
    if (hold_distortion) held.insert(held.end(), distortion.begin(), distortion.end());
    problem.SetManifold(lens.data(), held.empty() ? nullptr : new ceres::SubsetManifold(static_cast<int>(lens.size()), held));
  };
  auto set_sensor = [&](bool variable) {
    auto toggle = [&](double* block, const char* name) {
      if (variable && !options.fixed.count(name)) {
        problem.SetParameterBlockVariable(block);
      } else {
        problem.SetParameterBlockConstant(block);
      }
    };
    toggle(&m_mm, "m");
    toggle(tilt, "tilt");
    toggle(decenter, "decenter");
    if (!shape.empty()) toggle(shape.data(), "shape");
  };
  auto set_poses = [&](bool variable) {
    for (size_t v = 0; v < views; ++v) {
      if (!problem.HasParameterBlock(rotations[v].data())) continue;
      if (variable && !options.fixed.count("poses")) {
        problem.SetParameterBlockVariable(rotations[v].data());
        problem.SetParameterBlockVariable(translations[v].data());
      } else {
        problem.SetParameterBlockConstant(rotations[v].data());
        problem.SetParameterBlockConstant(translations[v].data());
      }
    }
  };
  // |residual| of every fitted corner at the current parameters (NaN if it cannot project).
  auto residual_norms = [&]() {
    std::vector<double> norms(residuals.size(), NAN);
    for (size_t k = 0; k < residuals.size(); ++k) {
      double value[2];
      if (!residuals[k].outlier && (*residuals[k].functor)(residuals[k].blocks.data(), value))
        norms[k] = std::hypot(value[0], value[1]);
    }
    return norms;
  };
  // A robust sigma per coordinate: |e| of a 2-D Gaussian has median 1.1774 sigma.
  auto robust_sigma = [&](std::vector<double> norms) {
    norms.erase(std::remove_if(norms.begin(), norms.end(), [](double n) { return !std::isfinite(n); }), norms.end());
    if (norms.empty()) return 1.0;
    std::nth_element(norms.begin(), norms.begin() + norms.size() / 2, norms.end());
    return norms[norms.size() / 2] / 1.1774;
  };

  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = 1e-16;
  solver.gradient_tolerance = 1e-16;
  solver.parameter_tolerance = 1e-15;
  solver.num_threads = 2;
  solver.logging_type = ceres::SILENT;
  // One progress step per solver iteration; a cancel aborts the solve and throws.
  ProgressReporter progress(options.progress, "fit", 0);
  progress.ThrowIfCancelled();
  IterationProgress iteration_progress(&progress);
  solver.callbacks.push_back(&iteration_progress);
  ceres::Solver::Summary summary;
  auto solve = [&]() {
    ceres::Solve(solver, &problem, &summary);
    progress.ThrowIfCancelled();
  };
  // Stage 0: the poses alone, through the guessed sensor.
  if (!options.fixed.count("poses")) {
    problem.SetParameterBlockConstant(lens.data());
    set_sensor(false);
    set_poses(true);
    solve();
  }
  // Stage 1: everything but the distortion; stage 2: everything asked for. The priors
  // weigh against the residuals left by the stage before (while the start is poor they are
  // large and so hold the sensor near its design: a continuation away from wrong basins).
  prior_noise_px = std::max(1e-3, robust_sigma(residual_norms()));
  set_poses(true);
  set_sensor(true);
  if (!distortion.empty()) {
    set_lens(true);
    solve();
    prior_noise_px = std::max(1e-3, robust_sigma(residual_norms()));
  }
  set_lens(false);
  solve();
  // Gross outliers (robust mode): beyond max(floor, k sigma) of a robust sigma, removed and
  // the fit repeated without them, under Huber. A view left with too few corners goes.
  if (options.robust_loss_px > 0.0) {
    const std::vector<double> norms = residual_norms();
    const double threshold = std::max(options.outlier_floor_px, options.outlier_sigmas * robust_sigma(norms));
    result.outlier_threshold_px = threshold;
    std::vector<size_t> view_inliers(views, 0);
    for (size_t k = 0; k < residuals.size(); ++k) {
      Residual& r = residuals[k];
      if (r.outlier) continue;
      if (!(norms[k] <= threshold)) {
        r.outlier = true;
        ++result.outliers;
        ++result.per_view_outliers[r.view];
        problem.RemoveResidualBlock(r.id);
      } else {
        ++view_inliers[r.view];
      }
    }
    for (size_t v = 0; v < views; ++v)
      if (result.view_left_out[v].empty() && view_inliers[v] < kMinCornersPerView)
        leave_out(v, std::to_string(result.per_view_outliers[v]) + " of " + std::to_string(view_residuals[v]) +
                         " corners rejected as outliers (beyond " + FormatPx(threshold) + ")");
    // A view that fits as a whole far worse than the others shows something else than
    // their board (a false or a bent board, a wrong size): its corners are not outliers one
    // by one, but together they pull the sensor.
    std::vector<double> view_square(views, 0.0), view_rms;
    for (size_t k = 0; k < residuals.size(); ++k)
      if (!residuals[k].outlier && std::isfinite(norms[k])) view_square[residuals[k].view] += norms[k] * norms[k];
    for (size_t v = 0; v < views; ++v)
      if (result.view_left_out[v].empty()) view_rms.push_back(std::sqrt(view_square[v] / view_inliers[v]));
    if (view_rms.size() >= 3) {
      std::vector<double> sorted = view_rms;
      std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
      const double median_rms = sorted[sorted.size() / 2];
      const double limit = std::max(options.outlier_floor_px, options.view_rms_ratio * median_rms);
      for (size_t v = 0, k = 0; v < views; ++v) {
        if (!result.view_left_out[v].empty()) continue;
        const double rms = view_rms[k++];
        if (rms > limit)
          leave_out(v, "its corners fit at " + FormatPx(rms) + " RMS, beyond " + FormatPx(limit) + " (" +
                           FormatNumber(options.view_rms_ratio) + " x the views' median " + FormatPx(median_rms) +
                           "): not the board the other views show (a false, bent or wrongly sized board)");
      }
    }
    const size_t fitted_views = std::count(result.view_left_out.begin(), result.view_left_out.end(), "");
    if (fitted_views < kMinViews) {
      result.solver_report = std::to_string(fitted_views) + " views are left after the outlier rule (" +
                             std::to_string(kMinViews) + " needed): the corners do not show one board through one sensor";
      return result;
    }
    loss->Reset(new ceres::HuberLoss(options.robust_loss_px), ceres::TAKE_OWNERSHIP);
    prior_noise_px = std::max(1e-3, robust_sigma(residual_norms()));
    solve();
  }

  // Plain residuals at the solution; the statistics are over the inliers.
  int inliers = 0;
  double sum = 0.0;
  int free_columns = 0;
  std::vector<double*> variable;
  auto statistics = [&]() {
    sum = 0.0;
    inliers = 0;
    for (const Residual& r : residuals) {
      double value[2];
      if (r.outlier || !(*r.functor)(r.blocks.data(), value)) continue;
      sum += value[0] * value[0] + value[1] * value[1];
      ++inliers;
    }
    std::vector<double*> all;
    problem.GetParameterBlocks(&all);
    variable.clear();
    free_columns = 0;
    for (double* b : all)
      if (!problem.IsParameterBlockConstant(b)) variable.push_back(b), free_columns += problem.ParameterBlockTangentSize(b);
    // The covariance's scale: sigma per coordinate with the fit's degrees of freedom.
    return std::sqrt(sum / std::max(1, 2 * inliers - free_columns));
  };
  result.sigma_px = statistics();
  // The priors' final weight: the noise the covariance is scaled by (so the two agree).
  if (!priors.empty() && std::abs(result.sigma_px - prior_noise_px) > 0.05 * prior_noise_px) {
    prior_noise_px = std::max(1e-6, result.sigma_px);
    solve();
    result.sigma_px = statistics();
  }
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.solver_report = summary.BriefReport();
  // A parameter that ends many tolerances from its design: the guess, the tolerance or the
  // data is wrong (a prior that strong against the data is no longer a weak one).
  for (const Prior& prior : priors) {
    if (problem.IsParameterBlockConstant(prior.block)) continue;  // held: noted below
    const double moved = std::abs(prior.block[prior.index] - prior.design) / prior.tolerance;
    if (moved > kToleranceConflict)
      result.tolerance_conflicts.push_back(prior.name + " ended " + FormatNumber(moved) + " tolerances (" +
                                           FormatNumber(prior.tolerance * prior.scale) + ") from its design value " +
                                           FormatNumber(prior.design * prior.scale) +
                                           ": the guess, its tolerance or the data is off");
  }
  std::vector<double> view_sum(views, 0.0);
  std::vector<int> view_count(views, 0);
  for (const Residual& r : residuals) {
    double value[2] = {NAN, NAN};
    // A left-out view has no fitted pose: its corners stay NaN ("dropped" in reports).
    if (!result.view_left_out[r.view].empty() || !(*r.functor)(r.blocks.data(), value)) continue;
    const Eigen::Vector2d e(value[0], value[1]);
    result.residuals_px[r.view][r.index] = e;
    if (r.outlier) continue;
    view_sum[r.view] += e.squaredNorm();
    ++view_count[r.view];
  }
  result.rms_px = std::sqrt(sum / std::max(1, inliers));
  for (size_t v = 0; v < views; ++v)
    result.per_view_rms_px.push_back(view_count[v] ? std::sqrt(view_sum[v] / view_count[v]) : NAN);

  // Covariance: (J^T J)^-1 at the solution, J the corner residuals over sigma with the
  // priors' rows 1 / tolerance beneath (the posterior of a Gaussian prior). The Jacobian's
  // columns differ by many orders of magnitude (a polynomial's c3 multiplies r^6), so they
  // are scaled to unit norm before the SVD: a truncated decomposition would otherwise
  // discard well-determined directions and report their variance as zero. The poses are
  // in it: the sensor's block of the inverse is its covariance with the poses marginalised.
  std::map<const double*, std::vector<int>> columns;  // free block -> column of each ambient entry, -1 if held
  {
    int column = 0;
    for (double* b : variable) {
      const int tangent = problem.ParameterBlockTangentSize(b), size = problem.ParameterBlockSize(b);
      std::vector<int> map(size, -1);
      if (b == lens.data() && tangent < size) {  // held entries of the lens: the free ones in order
        int t = 0;
        for (int k = 0; k < size; ++k)
          if (std::find(held_scale.begin(), held_scale.end(), k) == held_scale.end()) map[k] = column + t++;
      } else if (tangent == size) {
        for (int k = 0; k < size; ++k) map[k] = column + k;
      }
      columns[b] = map;
      column += tangent;
    }
  }
  for (const Prior& prior : priors) {
    const auto found = columns.find(prior.block);
    if (found == columns.end() || found->second[prior.index] < 0)
      result.tolerance_notes.push_back("the tolerance on " + prior.name + " is not used: the parameter is held");
  }
  Eigen::MatrixXd covariance_internal;
  if (options.compute_covariance) {
    std::vector<ceres::ResidualBlockId> data_blocks;
    for (const Residual& r : residuals)
      if (!r.outlier) data_blocks.push_back(r.id);
    ceres::Problem::EvaluateOptions evaluate;
    evaluate.parameter_blocks = variable;
    evaluate.residual_blocks = data_blocks;
    evaluate.apply_loss_function = false;
    ceres::CRSMatrix crs;
    const bool evaluated = !data_blocks.empty() && problem.Evaluate(evaluate, nullptr, nullptr, nullptr, &crs);
    std::vector<std::pair<int, double>> prior_rows;  // column, 1 / tolerance
    for (const Prior& prior : priors) {
      const auto found = columns.find(prior.block);
      if (found != columns.end() && found->second[prior.index] >= 0)
        prior_rows.push_back({found->second[prior.index], 1.0 / prior.tolerance});
    }
    if (!evaluated) crs.num_rows = crs.num_cols = 0, prior_rows.clear();
    Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(crs.num_rows + prior_rows.size(), crs.num_cols);
    const double inverse_sigma = 1.0 / std::max(result.sigma_px, 1e-12);
    for (int r = 0; r < crs.num_rows; ++r)
      for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) jacobian(r, crs.cols[k]) = crs.values[k] * inverse_sigma;
    for (size_t p = 0; p < prior_rows.size(); ++p) jacobian(crs.num_rows + p, prior_rows[p].first) = prior_rows[p].second;
    Eigen::VectorXd column_scale = jacobian.colwise().norm().transpose();
    if (evaluated && (column_scale.array() > 0.0).all() && jacobian.rows() >= jacobian.cols()) {
      const Eigen::MatrixXd scaled = jacobian * column_scale.cwiseInverse().asDiagonal();
      const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeThinV);
      const Eigen::VectorXd& singular = svd.singularValues();
      // Rank check on the scaled problem: a real degeneracy (a gauge left free) shows here.
      if (singular.minCoeff() > 1e-10 * singular.maxCoeff()) {
        result.covariance_ok = true;
        const Eigen::MatrixXd v = column_scale.cwiseInverse().asDiagonal() * svd.matrixV() * singular.cwiseInverse().asDiagonal();
        covariance_internal = v * v.transpose();
      }
    }
  }
  // The covariance of the sensor's free parameters in reported units, and each std.
  std::vector<std::pair<int, double>> covariance_rows;  // column, unit scale
  auto add = [&](const std::string& name, const double* block, int index, double scale) {
    ParameterEstimate estimate;
    estimate.name = name;
    estimate.value = block[index] * scale;
    estimate.fixed = problem.IsParameterBlockConstant(const_cast<double*>(block));  // after stage 2: as asked
    const auto found = columns.find(block);
    const int column = found == columns.end() ? -1 : found->second[index];
    if (column < 0) estimate.fixed = true;
    if (result.covariance_ok && column >= 0) {
      estimate.std = std::sqrt(std::max(0.0, covariance_internal(column, column))) * scale;
      covariance_rows.push_back({column, scale});
      result.covariance_names.push_back(name);
    }
    if (!estimate.fixed && !result.covariance_ok) estimate.std = NAN;  // undetermined: say so
    result.parameters.push_back(estimate);
  };
  ForEachParameter<LensD, ProfileD>(lens.data(), &m_mm, tilt, decenter, shape.data(), shape_count, add);
  if (options.fixed.count("lens_scale") && !options.fixed.count("lens"))
    for (size_t k = 0; k < (LensD::kIsOrthographic ? 1u : 2u); ++k) result.parameters[k].fixed = true, result.parameters[k].std = 0.0;
  if (options.fixed.count("distortion") && !options.fixed.count("lens") && !LensD::kIsOrthographic)
    for (size_t k = 4; k < 6; ++k) result.parameters[k].fixed = true, result.parameters[k].std = 0.0;
  result.covariance.resize(covariance_rows.size(), covariance_rows.size());
  for (size_t i = 0; i < covariance_rows.size(); ++i)
    for (size_t j = 0; j < covariance_rows.size(); ++j)
      result.covariance(i, j) = covariance_internal(covariance_rows[i].first, covariance_rows[j].first) *
                                covariance_rows[i].second * covariance_rows[j].second;

  Model fitted = WithBlocks(guess, lens.data(), m_mm, tilt, decenter, shape.data(), shape_count);
  // The written rim encloses every corner the sensor was fitted on (the fit lets
  // reflections stray up to 15 % past the guess's rim): remap tables and the image area
  // then cover all calibrated image.
  {
    Model wide = fitted;
    wide.rim_radius_mm = std::min(1.15 * guess.rim_radius_mm, 0.99 * guess.mirror.MaxRadiusMm());
    const Eigen::Matrix3d camera_from_mirror = fitted.pose.CameraFromMirrorRotation();
    const Eigen::Vector3d mirror_origin = fitted.pose.CameraFromMirrorTranslation();
    double widest_mm = fitted.rim_radius_mm;
    for (const Residual& r : residuals) {
      if (r.outlier) continue;
      const Eigen::Quaterniond rotation(rotations[r.view][3], rotations[r.view][0], rotations[r.view][1], rotations[r.view][2]);
      const Eigen::Vector3d in_camera = rotation * r.functor->point_in_target_mm +
                                        Eigen::Vector3d(translations[r.view][0], translations[r.view][1], translations[r.view][2]);
      Eigen::Vector3d mirror_point;
      if (wide.ReflectionPoint(in_camera, &mirror_point) != ProjectionStatus::kOk) continue;
      const Eigen::Vector3d in_mirror = camera_from_mirror.transpose() * (mirror_point - mirror_origin);
      widest_mm = std::max(widest_mm, std::hypot(in_mirror.x(), in_mirror.y()));
    }
    // A hair beyond the widest so that the corner itself projects inside.
    if (widest_mm > fitted.rim_radius_mm)
      fitted.rim_radius_mm = std::min(widest_mm * (1.0 + 1e-6), 0.99 * fitted.mirror.MaxRadiusMm());
  }
  result.sensor = Sensor(fitted);
  for (size_t v = 0; v < views; ++v) {
    TargetPose pose;
    pose.camera_from_target_rotation = Eigen::Quaterniond(rotations[v][3], rotations[v][0], rotations[v][1], rotations[v][2]);
    pose.camera_from_target_translation_mm = Eigen::Vector3d(translations[v][0], translations[v][1], translations[v][2]);
    result.poses.push_back(pose);
  }
  return result;
}

}  // namespace

namespace {

// Calls each(name, value pointer, unit scale) for every parameter of a sensor's concrete
// model, through copies of its blocks, and returns the model with the copies put back.
template <typename Model, typename Each>
Model WithEachParameter(Model model, const Each& each) {
  using LensD = typename Model::LensType;
  using ProfileD = typename Model::ProfileType;
  std::vector<double> lens(LensD::kNumParams), shape(8, 0.0);
  model.lens.ToParams(lens.data());
  double m = model.pose.m_mm, tilt[2] = {model.pose.tilt_x_rad, model.pose.tilt_y_rad},
         decenter[2] = {model.pose.decenter_x_mm, model.pose.decenter_y_mm};
  int count = 0;
  if constexpr (kPolynomial<ProfileD>) {
    count = model.mirror.NumParams();
    model.mirror.ToParams(shape.data());
  } else if constexpr (!kTabulated<ProfileD>) {
    count = ProfileD::kNumParams;
    model.mirror.ToParams(shape.data());
  }
  ForEachParameter<LensD, ProfileD>(lens.data(), &m, tilt, decenter, shape.data(), count, each);
  return WithBlocks(model, lens.data(), m, tilt, decenter, shape.data(), count);
}

}  // namespace

std::vector<ParameterEstimate> SensorParameters(const Sensor& sensor) {
  std::vector<ParameterEstimate> parameters;
  std::visit(
      [&](const auto& model) {
        WithEachParameter(model, [&](const std::string& name, double* block, int index, double scale) {
          ParameterEstimate e;
          e.name = name;
          e.value = block[index] * scale;
          parameters.push_back(e);
        });
      },
      sensor.model());
  return parameters;
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
        const auto changed = WithEachParameter(model, [&](const std::string&, double* block, int index, double scale) {
          if (next < values.size()) block[index] = values[next] / scale;
          ++next;
        });
        if (next != values.size())
          throw std::invalid_argument("SensorWithParameters: " + std::to_string(values.size()) + " values for " +
                                      std::to_string(next) + " parameters");
        return Sensor(changed);
      },
      sensor.model());
}

FitOptions FitOptions::DefaultsFor(const Sensor& sensor) {
  FitOptions options;
  if (std::string(sensor.lens_name()) == "orthographic") options.fixed = {"m", "decenter", "lens_scale"};
  // A sphere turned about its own centre is the same surface (only its rim moves): its
  // tilt is not observable; its centre, R (0, 0, A) + (dx, dy, m), is.
  if (std::string(sensor.profile_name()) == "sphere") options.fixed.insert("tilt");
  // A free polynomial mirror bends the radial mapping as the lens's radial distortion
  // does: k1, k2 are held and the mirror shape absorbs them. (Its fx is observable but
  // weakly: another fx with another polynomial looks almost the same; see docs/calibrate.md "What the data can observe".)
  if (std::string(sensor.profile_name()) == "polynomial" && std::string(sensor.lens_name()) == "pinhole")
    options.fixed.insert("distortion");
  return options;
}

std::string FitOptions::Check() const {
  static const std::set<std::string> kBlocks = {"lens", "lens_scale", "distortion", "m", "tilt", "decenter", "shape", "poses"};
  for (const std::string& name : fixed)
    if (!kBlocks.count(name))
      return "fixed: unknown block '" + name + "' (lens, lens_scale, distortion, m, tilt, decenter, shape, poses)";
  if (!(robust_loss_px >= 0.0)) return "robust_loss_px: must be >= 0";
  if (!(outlier_floor_px >= 0.0) || !(outlier_sigmas > 0.0) || !(view_rms_ratio > 1.0))
    return "outlier rule: outlier_floor_px >= 0, outlier_sigmas > 0 and view_rms_ratio > 1";
  if (max_iterations < 1) return "max_iterations: must be >= 1";
  return {};
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
  return std::visit([&](const auto& model) { return FitModel(model, target, detections, initial_poses, options); },
                    guess.model());
}

}  // namespace omnical
