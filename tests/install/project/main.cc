// A program that only projects: the sphere sensor of Ohte & Tsuzuki's Table 1 (rim 43.9 mm,
// A = 1.138 rim radii, m = 4.110 rim radii, a pinhole putting the rim 500 px from the
// centre), a point beside the mirror projected to its pixel and the pixel's ray traced back.
#include <Eigen/Geometry>

#include <cstdio>

#include "model/sensor.h"

int main() {
  using SphereSensor = omnical::Catadioptric<double, omnical::SphereProfile, omnical::PinholeLens>;
  SphereSensor model;
  model.rim_radius_mm = 43.9;
  model.mirror = omnical::SphereProfile<double>{1.138 * 43.9};
  model.pose = {4.110 * 43.9, 0.0, 0.0, 0.0, 0.0};  // m_mm, tilts, decenters
  const double rim_sag_mm = model.mirror.EvaluateSag(43.9 * 43.9).z;
  const double focal_px = 500.0 * (model.pose.m_mm + rim_sag_mm) / 43.9;  // the rim at 500 px
  model.lens = {focal_px, focal_px, 499.5, 499.5, 0.0, 0.0, 0.0, 0.0};
  model.image_width_px = model.image_height_px = 1000;
  const omnical::Sensor sensor(model);

  // A point in the camera frame (mm; z along the lens axis towards the mirror), ~10 rim
  // radii off the axis.
  const Eigen::Vector3d point(400.0, -150.0, 60.0);
  Eigen::Vector2d pixel;
  if (sensor.Project(point, &pixel) != omnical::ProjectionStatus::kOk) return 1;
  Eigen::Vector3d origin, direction;
  if (sensor.Unproject(pixel, &origin, &direction) != omnical::ProjectionStatus::kOk) return 1;
  // The ray leaves the mirror at `origin` (not the lens: the sensor is non-central).
  const double miss_mm = (point - origin).cross(direction).norm();
  std::printf("pixel (%.4f, %.4f); the ray through it misses the point by %.3g mm\n", pixel.x(), pixel.y(), miss_mm);
  return miss_mm < 1e-6 ? 0 : 1;
}
