#include "model/design/designed_sensor.h"

#include <cmath>
#include <memory>

namespace omnical {

double PixelPitchMm(const OdeDesign& design, int image_size_px) { return design.rho_end_mm / (0.49 * image_size_px); }

Sensor SensorFromOdeDesign(const OdeDesignSpec& spec, const OdeDesign& design, int image_size_px, const std::string& table_path) {
  std::vector<double> radius_mm, sag_mm;
  for (const ProfileSample& s : design.profile) {
    radius_mm.push_back(s.radius_mm);
    sag_mm.push_back(s.height_mm - design.profile.front().height_mm);
  }
  Catadioptric<double, TabulatedProfile, PinholeLens> model;
  model.mirror.spline = std::make_shared<const ProfileSpline>(radius_mm, sag_mm, design.profile.back().slope, design.profile.front().slope);
  model.mirror.source = table_path;
  const double focal_px = spec.focal_length_mm / PixelPitchMm(design, image_size_px);
  const double centre_px = 0.5 * (image_size_px - 1);
  model.lens = {focal_px, focal_px, centre_px, centre_px, 0.0, 0.0, 0.0, 0.0};
  model.pose = {design.profile.front().height_mm - spec.focal_length_mm, 0.0, 0.0, 0.0, 0.0};
  model.rim_radius_mm = design.t_end_mm;
  model.image_width_px = model.image_height_px = image_size_px;
  return Sensor(model);
}

double TracedHeightMm(const Sensor& sensor, const OdeDesignSpec& spec, double pitch_mm, double rho_mm, double distance_mm) {
  const double centre_px = 0.5 * (sensor.image_width_px() - 1);
  Eigen::Vector3d origin, direction;
  if (sensor.Unproject(Eigen::Vector2d(centre_px + rho_mm / pitch_mm, centre_px), &origin, &direction) != ProjectionStatus::kOk)
    return NAN;
  // |origin_xy + s direction_xy| = distance, the far root (the ray leaves the axis side).
  const double a = direction.head<2>().squaredNorm(), b = 2.0 * origin.head<2>().dot(direction.head<2>());
  const double c = origin.head<2>().squaredNorm() - distance_mm * distance_mm;
  const double discriminant = b * b - 4.0 * a * c;
  if (!(a > 0.0) || discriminant < 0.0) return NAN;
  const double s = (-b + std::sqrt(discriminant)) / (2.0 * a);
  if (!(s > 0.0)) return NAN;
  // Camera frame: the pinhole at the origin, z along the axis; the image plane is f below.
  return origin.z() + s * direction.z() + spec.focal_length_mm;
}

LawRatioCurve TraceLawRatio(const Sensor& sensor, const OdeDesignSpec& spec, double pitch_mm, double distance_mm,
                            double rho_from_mm, double rho_to_mm, int intervals) {
  LawRatioCurve curve;
  curve.distance_mm = distance_mm;
  const double scale = distance_mm / spec.distance_mm;
  double rho_prev = rho_from_mm, h_prev = TracedHeightMm(sensor, spec, pitch_mm, rho_prev, distance_mm);
  for (int i = 1; i <= intervals; ++i) {
    const double rho = rho_from_mm + (rho_to_mm - rho_from_mm) * i / intervals;
    const double h = TracedHeightMm(sensor, spec, pitch_mm, rho, distance_mm);
    const double law_step = spec.law.HeightMm(rho) - spec.law.HeightMm(rho_prev);
    curve.rho_mm.push_back(0.5 * (rho + rho_prev));
    curve.ratio.push_back((h - h_prev) / (law_step * scale));
    rho_prev = rho, h_prev = h;
  }
  return curve;
}

}  // namespace omnical
