#include "correction/viewpoint_error.h"

#include <algorithm>
#include <cmath>

#include "model/minimize_1d.h"

namespace omnical {

double ViewpointAngleErrorRad(const AxialRayQuantities& ray, double object_distance_mm, double v0_z_mm) {
  const double object_x = ray.x_mm + object_distance_mm * std::sin(ray.omega_rad);
  const double object_z = ray.z_mm - object_distance_mm * std::cos(ray.omega_rad);
  return std::atan2(object_x, v0_z_mm - object_z) - ray.omega_rad;
}

double ViewpointAngleErrorEq23Rad(const AxialRayQuantities& ray, double object_distance_mm, double v0_z_mm) {
  // Rotating the direction V0 -> T by -Omega gives tan(eps) = -v sin / (L + v cos) with
  // L = D + x / sin(Omega) the distance V -> T and v = z_V0 - z_V: the printed equation
  // with that v and the opposite sign of epsilon.
  const double v = v0_z_mm - ray.viewpoint_z_mm;
  const double s = std::sin(ray.omega_rad), c = std::cos(ray.omega_rad);
  return -std::atan2(v * s, object_distance_mm + ray.x_mm / s + v * c);
}

ParallaxCurve ComputeParallaxCurve(const std::vector<FieldSample>& field, double object_distance_mm, double v0_mm) {
  ParallaxCurve curve;
  curve.object_distance_mm = object_distance_mm;
  curve.v0_mm = v0_mm;
  for (const FieldSample& sample : field) {
    const double epsilon = ViewpointAngleErrorRad(sample.ray, object_distance_mm, v0_mm);
    const double pixels = epsilon * sample.dh_domega_px_per_rad;
    curve.omega_deg.push_back(sample.ray.omega_rad * 180.0 / M_PI);
    curve.x_mm.push_back(sample.ray.x_mm);
    curve.error_deg.push_back(epsilon * 180.0 / M_PI);
    curve.error_px.push_back(pixels);
    curve.max_abs_error_px = std::max(curve.max_abs_error_px, std::abs(pixels));
    curve.max_abs_error_deg = std::max(curve.max_abs_error_deg, std::abs(epsilon) * 180.0 / M_PI);
  }
  return curve;
}

double BestViewpointMm(const std::vector<FieldSample>& field, double object_distance_mm) {
  auto worst = [&](double v0) {
    double w = 0.0;
    for (const FieldSample& s : field)
      w = std::max(w, std::abs(ViewpointAngleErrorRad(s.ray, object_distance_mm, v0) * s.dh_domega_px_per_rad));
    return w;
  };
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (const FieldSample& s : field) {
    lo = std::min(lo, s.ray.viewpoint_z_mm);
    hi = std::max(hi, s.ray.viewpoint_z_mm);
  }
  const double margin = 0.1 * (hi - lo) + 1e-6;
  return MinimizeScanThenBrent(worst, lo - margin, hi + margin, 100);
}

}  // namespace omnical
