// How far a calibrated sensor's projection may be off at a distance the user cares about:
// the fit's covariance of the sensor parameters (poses marginalised, priors included)
// pushed through the projection of points at that distance, over the part of the image
// the calibration observed.
//
// The point of a pixel at distance D lies D mm along the pixel's ray from its reflection
// point (the seed paper's n = D / rim radius; D = kInfinityMm for infinity). Per point the
// predicted error is sqrt(trace(J C J^T)), J = d pixel / d parameters (central
// differences), C the covariance: the RMS length of the 2-D error vector, the same
// per-corner definition as omnical's reprojection RMS (per coordinate it is smaller by
// sqrt 2).
//
// J is taken after the best rigid alignment, as omnical diff and the cross-validation
// compare two calibrations (calib/projection_diff.h): the part of each parameter's pixel
// motion that a rigid motion of the frame explains (least squares over the field;
// rotation only at infinity) is removed. calibrate fits that motion once, at the boards'
// median distance, and applies it at every distance (align_at_mm): fitted per distance
// its translation grows with the distance and hides a zoom-like error far away (0.027
// px predicted at 10 m and 99.9 km, then 0.085 at infinity, on the README's
// calibration). Board poses absorb any rigid motion of the
// frame, so the data fix it only through small effects (a pinhole's principal point with
// the mirror's tilt and decenter nearly turns the camera; the dolly zoom, fx with m,
// nearly slides the mirror's rays along the axis): kept, that uncertainty of where the
// camera's frame sits dominated (6.5 px at n = 2 where the fit was 0.07 px off after
// alignment, calibration_trust_test.cc). It is still reported, as in_camera_frame_*.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "calib/bundle_fit.h"
#include "calib/detections.h"
#include "calib/target.h"
#include "model/object_distance.h"
#include "model/sensor.h"

namespace omnical {

inline constexpr double kInfinityMm = kMaxObjectDistanceMm;  // 100 km

// An annulus around the principal point: the radii the calibration's corners cover, all
// round (the mirror is rotationally symmetric; a user's panorama uses every azimuth).
struct ObservedField {
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
  double inner_radius_px = 0.0, outer_radius_px = 0.0;
};
ObservedField FieldOfCorners(const Sensor& sensor, const DetectionSet& detections);

// The camera-frame points distance_mm along the pixels' rays through the sensor, from
// their reflection points; NaN columns where a pixel does not unproject.
Eigen::Matrix3Xd PointsAlongRays(const Sensor& sensor, const std::vector<Eigen::Vector2d>& pixels, double distance_mm);

// Pixels on a square grid (step_px apart) inside the field and seen through the sensor.
std::vector<Eigen::Vector2d> FieldPixels(const Sensor& sensor, const ObservedField& field, double step_px);

struct PredictedError {
  double distance_mm = 0.0;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<double> std_px;  // per pixel (NaN where the point does not project)
  double median_px = 0.0, max_px = 0.0;  // over the predicted pixels
  int unpredicted = 0;                    // pixels whose point did not project
  double aligned_at_mm = NAN;             // where the alignment was fitted (NaN: none could be)
  bool aligned_once = false;              // at align_at_mm for every distance (else at this one)
  // The same with the frame's own uncertainty kept: points held fixed in the camera's
  // frame, no alignment (what matters only where that frame is itself used, e.g. the
  // camera's mount measured as the reference).
  std::vector<double> in_camera_frame_std_px;
  double in_camera_frame_median_px = 0.0, in_camera_frame_max_px = 0.0;
};

// One map per distance. `fit` supplies the parameters and covariance (FitResult's
// covariance_names order); throws std::invalid_argument without a covariance. align_at_mm
// NaN (or where too few field pixels project there): the alignment is fitted at each
// distance; aligned_at_mm says which.
std::vector<PredictedError> PredictProjectionError(const Sensor& sensor, const FitResult& fit,
                                                   const std::vector<Eigen::Vector2d>& pixels,
                                                   const std::vector<double>& distances_mm, double align_at_mm = NAN);

// |pixel of `other` - pixel| for the point at distance_mm along each pixel's ray through
// `reference`: how far another sensor (a calibration vs the truth, or two calibrations)
// misplaces the same objects. NaN where either does not project.
std::vector<double> ProjectionDisplacement(const Sensor& reference, const Sensor& other,
                                           const std::vector<Eigen::Vector2d>& pixels, double distance_mm);

// The median distance (mm) of the fitted views' corners from their reflection points,
// through the fitted sensor and poses: the default distance to predict the error at.
// NaN if no corner projects.
double MedianCornerDistanceMm(const Sensor& sensor, const CalibrationTarget& target, const DetectionSet& detections,
                              const FitResult& fit);

// Median and maximum of the finite values.
void MedianAndMax(std::vector<double> values, double* median, double* max);

}  // namespace omnical
