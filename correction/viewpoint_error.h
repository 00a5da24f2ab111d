// The viewpoint-distribution angle error of the seed paper (Ohte & Tsuzuki Sec. 4.2,
// Eq. 23): a central "virtual projector" at V0 on the mirror axis sends each pixel's ray
// from V0, but the real ray leaves the mirror at P with its own viewpoint V. An object T
// at distance D from P along the real ray is then seen from V0 at an angle off by
// epsilon; in the image that is epsilon * dh/dOmega pixels.
#pragma once

#include <vector>

#include "model/optics.h"

namespace omnical {

// epsilon (rad) for an object D mm from the reflection point along the ray, from the
// exact geometry: T = P + D (sin Omega, -cos Omega), epsilon = Omega'(V0 -> T) - Omega.
// Positive when V0 sees the object at a larger Omega (further from the -z axis).
double ViewpointAngleErrorRad(const AxialRayQuantities& ray, double object_distance_mm, double v0_z_mm);

// The same from Eq. 23 as printed, tan(eps) [n + x / sin(Omega) + v cos(Omega)] = v sin(Omega),
// in mm. The geometry fixes the signs the paper leaves open (SEED-NOTES): it holds with
// v = z_V0 - z_V (from V up to V0) for the error Omega - Omega'.
double ViewpointAngleErrorEq23Rad(const AxialRayQuantities& ray, double object_distance_mm, double v0_z_mm);

struct ParallaxCurve {
  double object_distance_mm = 0.0;
  double v0_mm = 0.0;  // V0 as z on the mirror axis, mirror frame
  std::vector<double> omega_deg, x_mm, error_deg, error_px;
  double max_abs_error_px = 0.0;
  double max_abs_error_deg = 0.0;
};

// The error over the whole field (0 < x <= rim) for a given V0.
ParallaxCurve ComputeParallaxCurve(const std::vector<FieldSample>& field, double object_distance_mm, double v0_mm);

// The V0 that minimises the worst absolute pixel error over the field (minimax; the
// worst error is quasi-convex in V0): coarse scan over the viewpoint range, then Brent.
double BestViewpointMm(const std::vector<FieldSample>& field, double object_distance_mm);

}  // namespace omnical
