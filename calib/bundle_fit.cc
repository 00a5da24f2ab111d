#include "calib/bundle_fit.h"

#include <ceres/ceres.h>

#include <Eigen/SVD>

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

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
template <typename LensD, typename ProfileD, typename Add>
void ForEachParameter(const double* lens, const double* m_mm, const double* tilt, const double* decenter,
                      const double* shape, int shape_count, const Add& add) {
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

template <typename Model>
FitResult FitModel(const Model& guess, const CalibrationTarget& target, const DetectionSet& detections,
                   const std::vector<TargetPose>& initial_poses, const FitOptions& options) {
  using LensD = typename Model::LensType;
  using ProfileD = typename Model::ProfileType;
  using Cost = decltype(CostFor(static_cast<const Model*>(nullptr)));
  FitResult result;

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
    }
  }
  if (residuals.empty()) {
    result.solver_report = "no observation could be projected through the initial guess";
    return result;
  }
  for (size_t v = 0; v < views; ++v)
    if (problem.HasParameterBlock(rotations[v].data())) problem.SetManifold(rotations[v].data(), new ceres::EigenQuaternionManifold);
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

  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = 1e-16;
  solver.gradient_tolerance = 1e-16;
  solver.parameter_tolerance = 1e-15;
  solver.num_threads = 2;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  // Stage 0: the poses alone, through the guessed sensor.
  if (!options.fixed.count("poses")) {
    problem.SetParameterBlockConstant(lens.data());
    set_sensor(false);
    set_poses(true);
    ceres::Solve(solver, &problem, &summary);
  }
  // Stage 1: everything but the distortion; stage 2: everything asked for.
  set_poses(true);
  set_sensor(true);
  if (!distortion.empty()) {
    set_lens(true);
    ceres::Solve(solver, &problem, &summary);
  }
  set_lens(false);
  ceres::Solve(solver, &problem, &summary);
  // Gross outliers (robust mode): residuals beyond 5 sigma, with sigma from the median
  // residual (a 2-D Gaussian's |e| has median 1.1774 sigma; P(|e| > 5 sigma) = 4e-6), are
  // removed and the fit repeated without them, under Huber.
  if (options.robust_loss_px > 0.0) {
    std::vector<double> norms;
    for (const Residual& r : residuals) {
      double value[2];
      if ((*r.functor)(r.blocks.data(), value)) norms.push_back(std::hypot(value[0], value[1]));
    }
    if (!norms.empty()) {
      std::nth_element(norms.begin(), norms.begin() + norms.size() / 2, norms.end());
      const double threshold = 5.0 * norms[norms.size() / 2] / 1.1774;
      for (Residual& r : residuals) {
        double value[2];
        if (!(*r.functor)(r.blocks.data(), value) || std::hypot(value[0], value[1]) > threshold) {
          r.outlier = true;
          ++result.outliers;
          problem.RemoveResidualBlock(r.id);
        }
      }
    }
    loss->Reset(new ceres::HuberLoss(options.robust_loss_px), ceres::TAKE_OWNERSHIP);
    ceres::Solve(solver, &problem, &summary);
  }
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.solver_report = summary.BriefReport();

  // Plain residuals at the solution; the statistics are over the inliers.
  double sum = 0.0;
  int inliers = 0;
  std::vector<double> view_sum(views, 0.0);
  std::vector<int> view_count(views, 0);
  for (const Residual& r : residuals) {
    double value[2] = {NAN, NAN};
    if (!(*r.functor)(r.blocks.data(), value)) continue;
    const Eigen::Vector2d e(value[0], value[1]);
    result.residuals_px[r.view][r.index] = e;
    if (r.outlier) continue;
    sum += e.squaredNorm();
    ++inliers;
    view_sum[r.view] += e.squaredNorm();
    ++view_count[r.view];
  }
  result.rms_px = std::sqrt(sum / std::max(1, inliers));
  for (size_t v = 0; v < views; ++v)
    result.per_view_rms_px.push_back(view_count[v] ? std::sqrt(view_sum[v] / view_count[v]) : NAN);

  // Standard deviations: (J^T J)^-1 at the solution, scaled by the residual variance
  // (the fit does not know the detection noise). The Jacobian's columns differ by many
  // orders of magnitude (a polynomial's c3 multiplies r^6), so they are scaled to unit
  // norm before the inversion: ceres::Covariance's truncated SVD would otherwise discard
  // well-determined directions and report their variance as zero.
  std::map<const double*, Eigen::VectorXd> variances;  // per free sensor block, ambient order
  if (options.compute_covariance) {
    std::vector<double*> variable;
    std::vector<double*> all;
    problem.GetParameterBlocks(&all);
    for (double* b : all)
      if (!problem.IsParameterBlockConstant(b)) variable.push_back(b);
    ceres::Problem::EvaluateOptions evaluate;
    evaluate.parameter_blocks = variable;
    evaluate.apply_loss_function = false;
    ceres::CRSMatrix crs;
    problem.Evaluate(evaluate, nullptr, nullptr, nullptr, &crs);
    Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
    for (int r = 0; r < crs.num_rows; ++r)
      for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) jacobian(r, crs.cols[k]) = crs.values[k];
    Eigen::VectorXd column_scale = jacobian.colwise().norm().transpose();
    const bool all_seen = (column_scale.array() > 0.0).all();
    if (all_seen) {
      const Eigen::MatrixXd scaled = jacobian * column_scale.cwiseInverse().asDiagonal();
      const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeThinV);
      const Eigen::VectorXd& sigma = svd.singularValues();
      // Rank check on the scaled problem: a real degeneracy (a gauge left free) shows here.
      if (sigma.minCoeff() > 1e-10 * sigma.maxCoeff()) {
        result.covariance_ok = true;
        const Eigen::MatrixXd v = svd.matrixV() * sigma.cwiseInverse().asDiagonal();
        const Eigen::VectorXd scaled_variance = v.rowwise().squaredNorm();
        const double residual_variance = sum / std::max(1, 2 * inliers - crs.num_cols);
        int column = 0;
        for (double* b : variable) {
          const int tangent = problem.ParameterBlockTangentSize(b), size = problem.ParameterBlockSize(b);
          Eigen::VectorXd block = Eigen::VectorXd::Zero(size);
          // Tangent coordinates: all of the block, or (lens with held scale) the free entries in order.
          std::vector<int> free;
          for (int k = 0; k < size; ++k) free.push_back(k);
          if (b == lens.data() && tangent < size) {
            free.clear();
            for (int k = 0; k < size; ++k)
              if (std::find(held_scale.begin(), held_scale.end(), k) == held_scale.end()) free.push_back(k);
          }
          if (static_cast<int>(free.size()) == tangent) {
            for (int t = 0; t < tangent; ++t)
              block(free[t]) = scaled_variance(column + t) / (column_scale(column + t) * column_scale(column + t)) * residual_variance;
            variances[b] = block;
          }
          column += tangent;
        }
      }
    }
  }
  auto add = [&](const std::string& name, const double* block, int index, double scale) {
    ParameterEstimate estimate;
    estimate.name = name;
    estimate.value = block[index] * scale;
    estimate.fixed = problem.IsParameterBlockConstant(const_cast<double*>(block));  // after stage 2: as asked
    const auto found = variances.find(block);
    if (found != variances.end()) estimate.std = std::sqrt(std::max(0.0, found->second(index))) * scale;
    if (!estimate.fixed && !result.covariance_ok) estimate.std = NAN;  // undetermined: say so
    result.parameters.push_back(estimate);
  };
  ForEachParameter<LensD, ProfileD>(lens.data(), &m_mm, tilt, decenter, shape.data(), shape_count, add);
  if (options.fixed.count("lens_scale") && !options.fixed.count("lens"))
    for (size_t k = 0; k < (LensD::kIsOrthographic ? 1u : 2u); ++k) result.parameters[k].fixed = true, result.parameters[k].std = 0.0;
  if (options.fixed.count("distortion") && !options.fixed.count("lens") && !LensD::kIsOrthographic)
    for (size_t k = 4; k < 6; ++k) result.parameters[k].fixed = true, result.parameters[k].std = 0.0;

  Model fitted = guess;
  fitted.lens = LensD::FromParams(lens.data());
  fitted.pose = MirrorPose<double>{m_mm, tilt[0], tilt[1], decenter[0], decenter[1]};
  if constexpr (kPolynomial<ProfileD>) {
    fitted.mirror = ProfileD::FromParams(shape.data(), shape_count);
  } else if constexpr (!kTabulated<ProfileD>) {
    fitted.mirror = ProfileD::FromParams(shape.data());
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

std::vector<ParameterEstimate> SensorParameters(const Sensor& sensor) {
  std::vector<ParameterEstimate> parameters;
  std::visit(
      [&](const auto& model) {
        using Model = std::decay_t<decltype(model)>;
        using LensD = typename Model::LensType;
        using ProfileD = typename Model::ProfileType;
        std::vector<double> lens(LensD::kNumParams), shape(8, 0.0);
        model.lens.ToParams(lens.data());
        const double m = model.pose.m_mm, tilt[2] = {model.pose.tilt_x_rad, model.pose.tilt_y_rad},
                     decenter[2] = {model.pose.decenter_x_mm, model.pose.decenter_y_mm};
        int count = 0;
        if constexpr (kPolynomial<ProfileD>) {
          count = model.mirror.NumParams();
          model.mirror.ToParams(shape.data());
        } else if constexpr (!kTabulated<ProfileD>) {
          count = ProfileD::kNumParams;
          model.mirror.ToParams(shape.data());
        }
        ForEachParameter<LensD, ProfileD>(lens.data(), &m, tilt, decenter, shape.data(), count,
                                          [&](const std::string& name, const double* block, int index, double scale) {
                                            ParameterEstimate e;
                                            e.name = name;
                                            e.value = block[index] * scale;
                                            parameters.push_back(e);
                                          });
      },
      sensor.model());
  return parameters;
}

FitOptions FitOptions::DefaultsFor(const Sensor& sensor) {
  FitOptions options;
  if (std::string(sensor.lens_name()) == "orthographic") options.fixed = {"m", "decenter", "lens_scale"};
  // A sphere turned about its own centre is the same surface (only its rim moves): its
  // tilt is not observable; its centre, R (0, 0, A) + (dx, dy, m), is.
  if (std::string(sensor.profile_name()) == "sphere") options.fixed.insert("tilt");
  // A free polynomial mirror bends the radial mapping as the lens's radial distortion
  // does: k1, k2 are held and the mirror shape absorbs them. (Its fx is observable but
  // weakly: another fx with another polynomial looks almost the same; see the README.)
  if (std::string(sensor.profile_name()) == "polynomial" && std::string(sensor.lens_name()) == "pinhole")
    options.fixed.insert("distortion");
  return options;
}

std::string FitOptions::Check() const {
  static const std::set<std::string> kBlocks = {"lens", "lens_scale", "distortion", "m", "tilt", "decenter", "shape", "poses"};
  for (const std::string& name : fixed)
    if (!kBlocks.count(name))
      return "--fix: unknown block '" + name + "' (lens, lens_scale, distortion, m, tilt, decenter, shape, poses)";
  if (!(robust_loss_px >= 0.0)) return "--loss-px: must be >= 0";
  if (max_iterations < 1) return "--max-iterations: must be >= 1";
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
  return std::visit([&](const auto& model) { return FitModel(model, target, detections, initial_poses, options); },
                    guess.model());
}

}  // namespace omnical
