// How differently two calibrations of one sensor place the same objects: the points at a
// distance along each field pixel's ray through the reference, moved by the rigid motion
// that best maps them into the other calibration's frame, projected through the other.
//
// Two calibrations of one camera each choose their own frame (the poses absorb any rigid
// motion of it), so the raw difference of their projections counts that choice as error.
// The best rigid alignment (least squares in pixels over the field; rotation only at
// infinity, where a translation moves nothing) removes it: what is left is what one
// calibration gets wrong relative to the other. This is the "projection difference" of
// mrcal's projection_diff, for non-central sensors: the points lie distance_mm along the
// ray from its reflection point (calib/predicted_error.h's convention; kInfinityMm for
// infinity). Lengths are per point: |difference| of the 2-D pixel vector, the same
// per-corner convention as omnical's RMS.
//
// By default the alignment is fitted at the compared distance itself, as mrcal's
// projection_diff fits its implied transform (and as the issue's "halves after the best
// rigid alignment at 2 m" is defined): the best agreement between objects all at that one
// distance. Far from where the boards were, its translation grows with the distance
// (16 mm at 2 m, 80 mm at 10 m between the real dev set's halves, boards at 0.2-0.45 m)
// and takes up a zoom-like disagreement no pose could absorb, so it reads low there: 0.29
// px at 2 m, 1.54 px at infinity, where only a rotation is fitted. With align_at_mm the
// one rigid motion fitted at that distance (the boards') is applied at every distance:
// 1.28 px at 2 m, continuous into infinity: what a scene spanning distances sees.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calib/detections.h"
#include "model/sensor.h"

namespace omnical {

struct ProjectionDiff {
  double distance_mm = 0.0;
  std::vector<Eigen::Vector2d> pixels;         // the field pixels compared (reference image)
  std::vector<Eigen::Vector2d> difference_px;  // other (aligned) - pixel; NaN where either does not project
  double rms_px = NAN, median_px = NAN, max_px = NAN;  // over the compared pixels
  int compared = 0;                             // pixels both sensors project
  // The alignment: other_frame = rotation * reference_frame + translation_mm.
  bool aligned = false;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation_mm = Eigen::Vector3d::Zero();
  double rotation_deg = 0.0;
  double aligned_at_mm = NAN;     // where the alignment was fitted: distance_mm unless align_at_mm was given
  double unaligned_rms_px = NAN;  // the same pixels before the alignment
  // Fitted at another distance, the motion can move a point off `other`'s mirror (past
  // its rim, widened 15 %): not compared, counted here.
  int moved_off_mirror = 0;
};

// Throws InputError when fewer than 6 field pixels project through both sensors (nothing
// to compare or to align on) at distance_mm or at align_at_mm, a distance is not > 0,
// align_at_mm is given without the alignment, or the motion fitted there leaves fewer than
// 6 field points on `other`'s mirror. align_at_mm NaN: fitted at distance_mm.
ProjectionDiff CompareProjections(const Sensor& reference, const Sensor& other, const std::vector<Eigen::Vector2d>& pixels,
                                  double distance_mm, bool align = true, double align_at_mm = NAN);

// The pixels to compare on, step_px apart: the annulus the detections' corners cover
// (calib/predicted_error.h's FieldOfCorners) or, without detections (null or empty),
// every pixel the reference sees through its mirror.
std::vector<Eigen::Vector2d> ComparisonField(const Sensor& reference, const DetectionSet* detections, double step_px);

}  // namespace omnical
