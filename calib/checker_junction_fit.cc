#include "calib/checker_junction_fit.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

#include "calib/bundle_fit.h"
#include "calib/printed_patch_fit.h"

namespace omnical {

namespace {

// A junction is kept this far inside the rim and more: its squares' fit holds the rim's
// position (the realistic renders' rim junctions lie 1-3 px inside it, each visible).
constexpr int kJunctionRimMarginPx = 0;

}  // namespace

bool FitCheckerJunction(const CalibrationTarget& target, const cv::Mat& grey, const Sensor& sensor, const BoardWarp& warp,
                        int id, const Eigen::Vector2d& start_px, const std::map<int, Eigen::Vector2d>& found_px,
                        Eigen::Vector2d* junction_px) {
  if (target.type() != CalibrationTarget::Type::kCheckerboard) return false;
  const int cols = target.cols();
  if (cols < 2 || target.rows() < 2 || id < 0 || id / cols >= target.rows()) return false;
  const int row = id / cols, col = id % cols;
  std::map<int, Eigen::Vector3d> board_mm;
  for (const TargetCorner& c : target.corners()) board_mm[c.id] = c.point_in_target;
  const Eigen::Vector2d square_mm((board_mm.at(1) - board_mm.at(0)).norm(), (board_mm.at(cols) - board_mm.at(0)).norm());

  // The start pose from the corners up to two squares around (this one included): where
  // the rim cuts the board, the next row in alone is a line.
  ImageDetections around;
  around.corners.push_back({id, start_px});
  Eigen::Vector2d half_box_px = Eigen::Vector2d::Zero();  // the region's reach in the image, from the corners around
  double step_px = 0.0;
  for (int dr = -2; dr <= 2; ++dr)
    for (int dc = -2; dc <= 2; ++dc) {
      const int r = row + dr, c = col + dc;
      if ((dr == 0 && dc == 0) || r < 0 || c < 0 || r >= target.rows() || c >= cols) continue;
      const auto it = found_px.find(r * cols + c);
      if (it == found_px.end()) continue;
      around.corners.push_back({it->first, it->second});
      half_box_px = half_box_px.cwiseMax((it->second - start_px).cwiseAbs() * 1.25 / std::max(std::abs(dr), std::abs(dc)));
      step_px = std::max(step_px, (it->second - start_px).norm() / std::hypot(dr, dc));
    }
  if (!(step_px >= 4.0 && step_px <= 400.0)) return false;
  // Too few of them, or on a line (a row along the rim: their board points' least spread
  // under a quarter square, where IPPE may still return a poor pose): the pose of all the
  // image's corners starts it instead (flat, the board's warp aside: close enough).
  Eigen::Vector2d mean_mm = Eigen::Vector2d::Zero();
  for (const CornerObservation& c : around.corners) mean_mm += board_mm.at(c.id).head<2>();
  mean_mm /= static_cast<double>(around.corners.size());
  Eigen::Matrix2d scatter_mm2 = Eigen::Matrix2d::Zero();
  for (const CornerObservation& c : around.corners) {
    const Eigen::Vector2d d = board_mm.at(c.id).head<2>() - mean_mm;
    scatter_mm2 += d * d.transpose() / static_cast<double>(around.corners.size());
  }
  const bool on_a_line =
      !(std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(scatter_mm2).eigenvalues()(0))) >=
        0.25 * square_mm.minCoeff());
  TargetPose start_pose;
  if (around.corners.size() < 4 || on_a_line || !InitialTargetPose(sensor, target, around, &start_pose)) {
    ImageDetections all;
    for (const auto& [corner_id, pixel] : found_px) all.corners.push_back({corner_id, pixel});
    if (!InitialTargetPose(sensor, target, all, &start_pose)) return false;
  }

  // Within 1.25 squares of the junction on the board: its four squares and the edges on to
  // the next junctions, which hold the grid's lines where the junction's own side is cut.
  const Eigen::Vector2d at_mm = board_mm.at(id).head<2>();
  PatchRegion region;
  // Not beyond the printed board (what lies there is unknown).
  region.board_low_mm = (at_mm - 1.25 * square_mm).cwiseMax(target.min_mm());
  region.board_high_mm = (at_mm + 1.25 * square_mm).cwiseMin(target.max_mm());
  // Searched: 1.25 squares around the junction as far as the corners around it reach on
  // either side (scaled), a quarter square more, the blur's reach and the rim's clearance.
  half_box_px += Eigen::Vector2d::Constant(0.25 * step_px + 4.0 + kRimClearancePx);
  region.image_low_px = start_px - half_box_px;
  region.image_high_px = start_px + half_box_px;
  region.on_mirror_px = {start_px};
  region.model_rim = true;
  region.core_low_mm = at_mm - 0.5 * square_mm;  // the junction's own half squares
  region.core_high_mm = at_mm + 0.5 * square_mm;
  // Twice: the pixels are chosen at the start pose, and a start from the whole image's pose
  // can be a square's fraction off.
  PatchFit patch;
  if (!FitPrintedPatch(target, grey, sensor, warp, start_pose, region, &patch) ||
      !FitPrintedPatch(target, grey, sensor, warp, patch.pose, region, &patch))
    return false;
  const Eigen::Vector3d on_board_mm(at_mm.x(), at_mm.y(), WarpedSurface::Of(target, warp).OffsetMm(at_mm.x(), at_mm.y()));
  const Eigen::Vector3d in_camera = patch.pose.camera_from_target_rotation * on_board_mm +
                                    patch.pose.camera_from_target_translation_mm;
  Eigen::Vector2d fitted_px;
  if (sensor.Project(in_camera, &fitted_px) != ProjectionStatus::kOk || !OnMirrorWithMargin(sensor, fitted_px, kJunctionRimMarginPx)) return false;
  if (!((fitted_px - start_px).norm() <= 0.25 * step_px)) return false;
  *junction_px = fitted_px;
  return true;
}

}  // namespace omnical
