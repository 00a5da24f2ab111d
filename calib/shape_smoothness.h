// A smoothness prior on a free-form profile's shape block, for the bundle fit
// (calib/bundle_fit.cc): the profile's SmoothnessResiduals (model/spline_profile.h: the
// curvature its knots add, as a ratio to the vertex's) over kSmoothnessStd, times the
// corner noise so that it weighs as a Gaussian prior of that std next to residuals in
// px (as the design tolerances do: PriorCost). Profiles without SmoothnessResiduals get
// none.
//
// The std: a steep sphere (Ohte's, A = 1.138 rim) adds 9 x the vertex curvature at the
// rim; kSmoothnessStd = 10 lets such a mirror be what the data say. Measured: on the
// rendered Ohte sphere (8 knots) the knots move by 0.01 of their std against no prior,
// on the real Mei set (6 and 8 knots) by less; a std of 1 already slid the sphere's fit
// along its fx-m valley (fx 1196 -> 981 px, std 95). What it is for: a knot no corner
// constrains (the control value past the span when the reflections stop short of it)
// left the Mei fit's covariance singular without it.
#pragma once

#include <ceres/ceres.h>

#include <type_traits>
#include <utility>

namespace omnical {

constexpr double kSmoothnessStd = 10.0;

template <typename Profile, typename = void>
constexpr bool kHasShapeSmoothness = false;
template <typename Profile>
constexpr bool kHasShapeSmoothness<Profile, std::void_t<decltype(std::declval<Profile>().NumSmoothnessResiduals())>> =
    true;

template <typename Profile>
class ShapeSmoothnessCost {
 public:
  // profile: the guess's (its parameter count and the scale of its residuals); noise_px:
  // the fit's current corner noise, read at every evaluation.
  ShapeSmoothnessCost(const Profile& profile, const double* noise_px) : profile_(profile), noise_px_(noise_px) {}

  template <typename T>
  bool operator()(T const* const* shape, T* residuals) const {
    profile_.SmoothnessResiduals(shape[0], residuals);
    const T weight(*noise_px_ / kSmoothnessStd);
    for (int j = 0; j < profile_.NumSmoothnessResiduals(); ++j) residuals[j] *= weight;
    return true;
  }

  static ceres::CostFunction* Create(const Profile& profile, const double* noise_px) {
    auto* cost = new ceres::DynamicAutoDiffCostFunction<ShapeSmoothnessCost, 8>(new ShapeSmoothnessCost(profile, noise_px));
    cost->AddParameterBlock(profile.NumParams());
    cost->SetNumResiduals(profile.NumSmoothnessResiduals());
    return cost;
  }

 private:
  Profile profile_;
  const double* noise_px_;
};

}  // namespace omnical
