// Which mirror family an unknown mirror is fitted as, chosen by how well each predicts
// views it was not fitted to (calib/fold_scores.h): the 3-term even polynomial, or the
// even asphere (a conic: sphere, paraboloid, hyperboloid, ellipsoid). Without a guess the
// polynomial alone was the default; through it a sphere's corners fit (the realistic
// checkerboard render, 0.065 px RMS) but its extrapolation past the corners does not
// (0.153 px from the true sensor at 300 mm against the conic's 0.015), and the rim's
// boards, which only that extrapolation can find, were lost. A conic's curvature
// continues past the corners; a free polynomial's highest terms grow fastest exactly there
// (calib/rim_circle.h lets the images' rim widen a conic's search further for that).
#pragma once

#include <string>
#include <vector>

#include "model/model_registry.h"

namespace omnical {

// CalibrationOptions::profile: choose here (without a guess).
inline constexpr const char* kChooseProfile = "auto";
// The first is the rim circle's start the lens is chosen through; the even asphere is
// kept only where it predicts better by more than kProfileScoreTolerance (the knots' and
// the lens's parsimony rule). On the real dev set (a paraboloid) the two score within
// 0.6 % and the polynomial stays.
inline const std::vector<std::string> kProfileCandidates = {"polynomial", "even_asphere"};
constexpr double kProfileScoreTolerance = 0.01;

// What CalibrationOptions::profile accepts: the families the fit can shape, or kChooseProfile.
inline std::vector<std::string> CalibrationProfileNames() {
  std::vector<std::string> names = ProfileNames(false);
  names.push_back(kChooseProfile);
  return names;
}

}  // namespace omnical
