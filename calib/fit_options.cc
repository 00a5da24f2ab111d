#include "calib/fit_options.h"

#include <cmath>
#include <iterator>

#include "model/model_registry.h"

namespace omnical {

namespace {

// Each refine switch with the block name --fix holds it by and the parameter group it
// moves: the one place the names live. "lens" holds the first four together.
struct RefineSwitch {
  const char* name;
  bool RefineOptions::*member;
  ParameterGroup group;
  bool is_group;  // poses move no sensor parameter
};
constexpr RefineSwitch kSwitches[] = {
    {"lens_scale", &RefineOptions::focal, ParameterGroup::kFocal, true},
    {"principal_point", &RefineOptions::principal_point, ParameterGroup::kPrincipalPoint, true},
    {"distortion", &RefineOptions::distortion, ParameterGroup::kDistortion, true},
    {"tangential", &RefineOptions::tangential, ParameterGroup::kTangential, true},
    {"m", &RefineOptions::m, ParameterGroup::kMirrorDistance, true},
    {"tilt", &RefineOptions::tilt, ParameterGroup::kTilt, true},
    {"decenter", &RefineOptions::decenter, ParameterGroup::kDecenter, true},
    {"shape", &RefineOptions::shape, ParameterGroup::kShape, true},
    {"poses", &RefineOptions::poses, ParameterGroup::kShape, false},
};
constexpr int kLensSwitches = 4;

const RefineSwitch& SwitchOf(ParameterGroup group) {
  for (const RefineSwitch& s : kSwitches)
    if (s.is_group && s.group == group) return s;
  return kSwitches[0];  // unreachable: every group has a switch
}

}  // namespace

bool RefineOptions::Refines(ParameterGroup group) const { return this->*SwitchOf(group).member; }

const char* HoldName(ParameterGroup group) { return SwitchOf(group).name; }

std::string RefineOptions::Hold(const std::set<std::string>& names) {
  for (const std::string& name : names) {
    bool known = name == "lens";
    for (int k = 0; k < static_cast<int>(std::size(kSwitches)); ++k)
      if (name == kSwitches[k].name || (name == "lens" && k < kLensSwitches)) {
        this->*kSwitches[k].member = false;
        known = true;
      }
    if (!known) {
      std::string all = "lens";
      for (const RefineSwitch& s : kSwitches) all += std::string(", ") + s.name;
      return "fixed: unknown block '" + name + "' (" + all + ")";
    }
  }
  return {};
}

std::set<std::string> RefineOptions::HeldNames() const {
  std::set<std::string> names;
  const bool whole_lens = !focal && !principal_point && !distortion && !tangential;
  if (whole_lens) names.insert("lens");
  for (int k = whole_lens ? kLensSwitches : 0; k < static_cast<int>(std::size(kSwitches)); ++k)
    if (!(this->*kSwitches[k].member)) names.insert(kSwitches[k].name);
  return names;
}

bool RefineOptions::RefinesSensor() const {
  for (const RefineSwitch& s : kSwitches)
    if (s.is_group && this->*s.member) return true;
  return false;
}

RefineOptions RefineOptions::PosesOnly() {
  RefineOptions only;
  for (const RefineSwitch& s : kSwitches)
    if (s.is_group) only.*s.member = false;
  return only;
}

ceres::Solver::Options DefaultSolverOptions() {
  ceres::Solver::Options solver;
  // The poses eliminated (Schur complement, the bundle-adjustment structure): the same
  // steps as a dense QR of the whole Jacobian; on the 30 fits of
  // PredictedError.MonteCarloSpreadMatchesThePrediction 41 s on one thread against 56 s
  // (73 s of CPU) for the dense QR on two, every printed figure identical. One thread:
  // Ceres' Schur eliminator sums its blocks in thread order, so on two the same calibration
  // run twice differed in the 8th digit (the CLI and the Python module must agree,
  // tests/python/test_calib.py).
  solver.linear_solver_type = ceres::DENSE_SCHUR;
  solver.max_num_iterations = 200;
  solver.function_tolerance = 1e-12;
  solver.gradient_tolerance = 1e-16;
  solver.parameter_tolerance = 1e-15;
  solver.num_threads = 1;
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
        // A decentred lens (p1, p2) trades with the mirror's decenter and the principal
        // point: held unless asked for or chosen by held-out folds (calib/tangential_choice.h).
        if constexpr (!Model::kOrthographic) options.refine.tangential = false;
      },
      sensor.model());
  return options;
}

std::string FitOptions::Check() const {
  if (!(robust_loss_px >= 0.0)) return "robust_loss_px: must be >= 0";
  if (!(outlier_floor_px >= 0.0) || !(outlier_sigmas > 0.0) || !(outlier_bulk_sigmas >= outlier_sigmas) ||
      !(view_rms_ratio > 1.0))
    return "outlier rule: outlier_floor_px >= 0, outlier_sigmas > 0, outlier_bulk_sigmas >= outlier_sigmas and "
           "view_rms_ratio > 1";
  if (solver.max_num_iterations < 1) return "max_iterations: must be >= 1";
  if (threads < 1) return "threads: must be >= 1";
  // The threads work through an evaluation callback, which Ceres refuses with inner iterations.
  if (threads > 1 && solver.use_inner_iterations) return "threads: more than 1 needs solver.use_inner_iterations off";
  if (!std::isfinite(board_warp.x_mm) || !std::isfinite(board_warp.y_mm)) return "board_warp: must be finite";
  for (const auto& [id, offset_mm] : board_warp.relief_mm)
    if (!std::isfinite(offset_mm)) return "board_warp: relief of corner " + std::to_string(id) + " must be finite";
  if (fit_board_relief && !fit_board_warp) return "fit_board_relief: needs fit_board_warp";
  if (std::string why; !solver.IsValid(&why)) return "solver: " + why;
  return {};
}

}  // namespace omnical
