#include "calib/fit_options.h"

#include <cmath>

#include "model/model_registry.h"

namespace omnical {

bool RefineOptions::Refines(ParameterGroup group) const {
  switch (group) {
    case ParameterGroup::kFocal: return focal;
    case ParameterGroup::kPrincipalPoint: return principal_point;
    case ParameterGroup::kDistortion: return distortion;
    case ParameterGroup::kMirrorDistance: return m;
    case ParameterGroup::kTilt: return tilt;
    case ParameterGroup::kDecenter: return decenter;
    case ParameterGroup::kShape: return shape;
  }
  return true;
}

const char* HoldName(ParameterGroup group) {
  switch (group) {
    case ParameterGroup::kFocal: return "lens_scale";
    case ParameterGroup::kPrincipalPoint: return "principal_point";
    case ParameterGroup::kDistortion: return "distortion";
    case ParameterGroup::kMirrorDistance: return "m";
    case ParameterGroup::kTilt: return "tilt";
    case ParameterGroup::kDecenter: return "decenter";
    case ParameterGroup::kShape: return "shape";
  }
  return "?";
}

std::string RefineOptions::Hold(const std::set<std::string>& names) {
  for (const std::string& name : names) {
    if (name == "lens") {
      focal = principal_point = distortion = false;
    } else if (name == "lens_scale") {
      focal = false;
    } else if (name == "principal_point") {
      principal_point = false;
    } else if (name == "distortion") {
      distortion = false;
    } else if (name == "m") {
      m = false;
    } else if (name == "tilt") {
      tilt = false;
    } else if (name == "decenter") {
      decenter = false;
    } else if (name == "shape") {
      shape = false;
    } else if (name == "poses") {
      poses = false;
    } else {
      return "fixed: unknown block '" + name +
             "' (lens, lens_scale, principal_point, distortion, m, tilt, decenter, shape, poses)";
    }
  }
  return {};
}

std::set<std::string> RefineOptions::HeldNames() const {
  std::set<std::string> names;
  if (!focal && !principal_point && !distortion) {
    names.insert("lens");
  } else {
    if (!focal) names.insert("lens_scale");
    if (!principal_point) names.insert("principal_point");
    if (!distortion) names.insert("distortion");
  }
  if (!m) names.insert("m");
  if (!tilt) names.insert("tilt");
  if (!decenter) names.insert("decenter");
  if (!shape) names.insert("shape");
  if (!poses) names.insert("poses");
  return names;
}

ceres::Solver::Options DefaultSolverOptions() {
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = 200;
  solver.function_tolerance = 1e-16;
  solver.gradient_tolerance = 1e-16;
  solver.parameter_tolerance = 1e-15;
  solver.num_threads = 2;
  solver.logging_type = ceres::SILENT;
  return solver;
}

FitOptions FitOptions::DefaultsFor(const Sensor& sensor) {
  FitOptions options;
  std::visit(
      [&](const auto& model) {
        using Model = std::decay_t<decltype(model)>;
        // An orthographic lens only shifts m along the axis, sees the decenter as its
        // principal point and leaves one scale free (pixel scale x mirror size).
        if constexpr (Model::kOrthographic) options.refine.m = options.refine.decenter = options.refine.focal = false;
        // A sphere turned about its own centre is the same surface (only its rim moves):
        // its tilt is not observable; its centre, R (0, 0, A) + (dx, dy, m), is.
        if (!model.mirror.TiltObservable()) options.refine.tilt = false;
        // Free-form mirror terms bend the radial mapping as the lens's radial distortion
        // does: k1, k2 are held and the mirror shape absorbs them. (fx stays observable but
        // weakly: another fx with other terms looks almost the same; see docs/calibrate.md
        // "What the data can observe".)
        if constexpr (!Model::kOrthographic)
          if (HasFreeFormTerms(model.mirror)) options.refine.distortion = false;
      },
      sensor.model());
  return options;
}

std::string FitOptions::Check() const {
  if (!(robust_loss_px >= 0.0)) return "robust_loss_px: must be >= 0";
  if (!(outlier_floor_px >= 0.0) || !(outlier_sigmas > 0.0) || !(view_rms_ratio > 1.0))
    return "outlier rule: outlier_floor_px >= 0, outlier_sigmas > 0 and view_rms_ratio > 1";
  if (solver.max_num_iterations < 1) return "max_iterations: must be >= 1";
  if (std::string why; !solver.IsValid(&why)) return "solver: " + why;
  return {};
}

}  // namespace omnical
