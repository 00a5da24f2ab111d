// The best-fit central model of a non-central sensor, for tools that accept only central
// cameras (SLAM/VIO stacks, cv::omnidir, OCamCalib users). The sensor's exact rays, cut by
// the object surface at distance D around V0 (or at infinity), give 3-D points seen from
// V0; a central model at V0 is fitted to their pixels (Ceres, px residuals), and its
// error over the field is what a user of the export gets wrong for objects at D.
//
// Frames. A catadioptric image is mirror-reversed: no rotation of the camera frame makes it
// a central camera with positive focal lengths, so each export states its frame as
// central_from_mirror (3x3, determinant -1) applied to (point_in_mirror - V0):
// - mei (cv::omnidir, Mei & Rives 2007): z towards the direction the image centre sees;
// - ocamcalib (Scaramuzza 2006): x along image rows, y along columns, z along the mirror
//   axis away from the camera, as OCamCalib's cam2world returns them.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "correction/object_surface.h"
#include "model/sensor.h"

namespace omnical {

// Exact samples of the sensor over its field: omni pixels and their object points.
struct CentralFitSamples {
  std::vector<Eigen::Vector2d> pixels;           // omni px
  std::vector<Eigen::Vector3d> points_in_mirror;  // mm, on the surface
  std::vector<double> omega_deg;                  // each ray's angle from the mirror axis
};

// Pixels on a grid of `step_px` over the image whose rays see the mirror, cut by
// `surface` around V0 = (0, 0, v0_mm) (mirror frame).
CentralFitSamples SampleField(const Sensor& sensor, const ObjectSurface& surface, double v0_mm, double step_px);

struct ApproximationError {
  double rms_px = 0.0, max_px = 0.0;
  std::vector<double> omega_deg, error_px;  // per sample
};

struct MeiModel {
  double fx = 0, fy = 0, cx = 0, cy = 0, skew = 0;  // K = [fx s cx; 0 fy cy; 0 0 1]
  double xi = 1.0;
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0;  // cv::omnidir's D
  Eigen::Matrix3d central_from_mirror = Eigen::Matrix3d::Identity();
  double v0_mm = 0.0;
  // cv::omnidir::projectPoints' formula; false behind the model's horizon.
  bool Project(const Eigen::Vector3d& point_in_mirror, Eigen::Vector2d* pixel) const;
};

struct OCamModel {
  std::vector<double> pol;     // cam2world: z = pol[0] + pol[1] rho + ... (pol[1] = 0)
  std::vector<double> invpol;  // world2cam: rho = invpol[0] + invpol[1] theta + ...
  double xc_row = 0, yc_col = 0;  // centre, 0-based (C convention)
  double c = 1, d = 0, e = 0;     // affine
  int height = 0, width = 0;
  Eigen::Matrix3d central_from_mirror = Eigen::Matrix3d::Identity();
  double v0_mm = 0.0;
  // OCamCalib's world2cam (ocam_functions.c), returning (u, v) = (col, row).
  bool Project(const Eigen::Vector3d& point_in_mirror, Eigen::Vector2d* pixel) const;
};

// Fits; throws std::runtime_error if the samples are too few.
MeiModel FitMei(const CentralFitSamples& samples, double v0_mm);
OCamModel FitOCam(const Sensor& sensor, const CentralFitSamples& samples, double v0_mm);

template <typename Model>
ApproximationError ErrorOf(const Model& model, const CentralFitSamples& samples) {
  ApproximationError error;
  double sum = 0.0;
  for (size_t i = 0; i < samples.pixels.size(); ++i) {
    Eigen::Vector2d pixel;
    const double e = model.Project(samples.points_in_mirror[i], &pixel) ? (pixel - samples.pixels[i]).norm() : HUGE_VAL;
    error.omega_deg.push_back(samples.omega_deg[i]);
    error.error_px.push_back(e);
    sum += e * e;
    error.max_px = std::max(error.max_px, e);
  }
  error.rms_px = samples.pixels.empty() ? 0.0 : std::sqrt(sum / samples.pixels.size());
  return error;
}

}  // namespace omnical
