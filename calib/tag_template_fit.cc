#include "calib/tag_template_fit.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <optional>

#include "calib/bundle_fit.h"
#include "model/types.h"
#include "calib/printed_patch_fit.h"

namespace omnical {

bool FitTagTemplate(const CalibrationTarget& target, const cv::Mat& grey, const Sensor& sensor, const BoardWarp& warp,
                    int tag, const std::array<Eigen::Vector2d, 4>& start_px, TagTemplateFit* fit, bool across_rim,
                    const std::array<double, 4>& max_move_cells) {
  if (target.type() != CalibrationTarget::Type::kAprilGrid || target.family() != "tag36h11") return false;
  std::array<Eigen::Vector2d, 4> board_corners;
  int have = 0;
  for (const TargetCorner& c : target.corners())
    if (c.id / 4 == tag) board_corners[c.id % 4] = c.point_in_target.head<2>(), ++have;
  if (have != 4) return false;
  const double cell_mm = target.tag_size_mm() / 8.0;

  // Across the rim only a tag the rim cuts or comes near: a corner within the clearance of
  // a pixel beyond the mirror's rim (not the camera's reflection, which is kept clear of).
  if (across_rim) {
    bool at_rim = false;
    for (const Eigen::Vector2d& corner : start_px)
      for (int dv = -kRimClearancePx; dv <= kRimClearancePx && !at_rim; ++dv)
        for (int du = -kRimClearancePx; du <= kRimClearancePx && !at_rim; ++du) {
          Eigen::Vector3d origin, direction;
          const ProjectionStatus status = sensor.Unproject(corner + Eigen::Vector2d(du, dv), &origin, &direction);
          at_rim = status == ProjectionStatus::kOutsideMirror || status == ProjectionStatus::kMissesMirror;
        }
    if (!at_rim) return false;
  }
  // The start pose: InitialTargetPose on the four corners (a central approximation; the
  // fit then uses every pixel's own ray); across the rim through a wider mirror of the same
  // shape, which sees the corners beyond it.
  std::optional<Sensor> wider;
  if (across_rim) wider = SensorWithWiderRim(sensor, 1.15);
  const Sensor& wide = across_rim ? *wider : sensor;
  double edge_px = 0.0;
  for (int k = 0; k < 4; ++k) edge_px = std::max(edge_px, (start_px[(k + 1) % 4] - start_px[k]).norm());
  if (!(edge_px >= 4.0 && edge_px <= 400.0)) return false;
  ImageDetections corners;
  for (int k = 0; k < 4; ++k) corners.corners.push_back({4 * tag + k, start_px[k]});
  TargetPose start_pose;
  if (!InitialTargetPose(wide, target, corners, &start_pose)) return false;

  // The pixels within one cell of the tag's black square (data bits and gap included),
  // searched a cell and more around its corners: one cell beyond the square, the blur's
  // reach and the rim's clearance around that. No corner may be near the rim, unless the
  // rim is modelled.
  PatchRegion region;
  // Across the rim the neighbouring tags too (half of the tag may be all there is of it).
  const double reach_mm = across_rim ? target.tag_size_mm() * (1.0 + target.spacing_ratio()) : cell_mm;
  region.board_low_mm = (board_corners[0] - Eigen::Vector2d::Constant(reach_mm)).cwiseMax(target.min_mm());
  region.board_high_mm = (board_corners[2] + Eigen::Vector2d::Constant(reach_mm)).cwiseMin(target.max_mm());
  Eigen::Vector2d box_low = start_px[0], box_high = start_px[0];
  for (const Eigen::Vector2d& p : start_px) box_low = box_low.cwiseMin(p), box_high = box_high.cwiseMax(p);
  const double margin_px = (across_rim ? 1.3 : 0.25) * edge_px + 4.0 + kRimClearancePx;
  region.image_low_px = box_low - Eigen::Vector2d::Constant(margin_px);
  region.image_high_px = box_high + Eigen::Vector2d::Constant(margin_px);
  if (across_rim) {
    region.model_rim = true;
    region.core_low_mm = board_corners[0];  // the tag's own square: the neighbours must not stand in for it
    region.core_high_mm = board_corners[2];
  } else {
    region.clear_px.assign(start_px.begin(), start_px.end());
  }
  PatchFit patch;
  if (!FitPrintedPatch(target, grey, sensor, warp, start_pose, region, &patch)) return false;

  TagTemplateFit result;
  result.blur_px = patch.blur_px;
  result.contrast = patch.contrast;
  result.rms_grey = patch.rms_grey;
  result.pixels = patch.pixels;
  result.rim_shift_px = patch.rim_shift_px;
  // In cells of the tag's longest side. Along its most foreshortened side that is more
  // than a cell, but where the edge profiles failed the start is the detector's corner, off
  // by ~1 px radially near the rim (a bound of half a short cell, at least 1 px, refused 5
  // good rim tags on the realistic set); a fit one bit column over there shows in its
  // residual, which the caller compares with the image's other tags (a bound of a whole
  // cell would let a fit one bit column over pass on its corners alone).
  const double cell_px = edge_px / 8.0;
  const WarpedSurface surface = WarpedSurface::Of(target, warp);
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d corner_in_camera =
        patch.pose.camera_from_target_rotation *
            Eigen::Vector3d(board_corners[k].x(), board_corners[k].y(), surface.OffsetMm(board_corners[k].x(), board_corners[k].y())) +
        patch.pose.camera_from_target_translation_mm;
    if (wide.Project(corner_in_camera, &result.corners_px[k]) != ProjectionStatus::kOk) return false;
    if (!((result.corners_px[k] - start_px[k]).norm() <= max_move_cells[k] * std::max(cell_px, 1.0))) return false;
    // Across the rim, measured from the rim the fit placed: the sensor's (a fit's, moved
    // onto the images' rim circle) sat 1-2 px inside the image's on the realistic aprilgrid
    // seeds, and seed 3's rim tags lost corners 2-3.4 px inside the true rim that were
    // 0.04-0.06 px from the truth. The wider mirror still keeps them off the camera's
    // reflection.
    result.on_mirror[k] =
        across_rim ? InsideRimPx(sensor, wide, result.corners_px[k]) + patch.rim_shift_px >= kFittedRimMarginPx &&
                         OnMirrorWithMargin(wide, result.corners_px[k], kCornerRimMarginPx)
                   : OnMirrorWithMargin(sensor, result.corners_px[k], kCornerRimMarginPx);
    if (!across_rim && !result.on_mirror[k]) return false;
  }
  if (std::count(result.on_mirror.begin(), result.on_mirror.end(), true) == 0) return false;
  *fit = result;
  return true;
}

}  // namespace omnical
