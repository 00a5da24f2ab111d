// A printed board is rarely flat: paper on card bends, a hand-held board sags. The warp is
// the board's out-of-plane shape, a paraboloid along each board axis (mrcal's
// calobject_warp): z = x_mm (1 - u^2) + y_mm (1 - v^2) along the board's normal, u and v
// the corner's position scaled to [-1, 1] over the extent of the board's corners. So x_mm
// and y_mm are the deflections at the centre relative to the edges, in mm. One warp per
// board, shared by every view (the same sheet in every image).
//
// The relief: optionally each corner's own out-of-plane offset on top of the paraboloid
// (mm, per corner id; absent ids 0), for a board whose shape the paraboloid cannot follow
// (a card bent at one corner, a sheet glued unevenly). Shared by every view as well: it
// is the board's shape, not each view's. On the real Mei set the paraboloid leaves a shape
// that recurs across views: per-corner offsets learnt on nine views predicted the tenth's
// corners 22 % better (docs/calibrate.md, "Bent boards").
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <map>

#include "calib/target.h"

namespace omnical {

struct BoardWarp {
  BoardWarp() = default;
  BoardWarp(double along_x_mm, double along_y_mm) : x_mm(along_x_mm), y_mm(along_y_mm) {}

  double x_mm = 0.0, y_mm = 0.0;
  std::map<int, double> relief_mm;  // per corner id; empty without a relief

  // Per corner id the factors (1 - u^2, 1 - v^2) the deflections multiply.
  static std::map<int, Eigen::Vector2d> Basis(const CalibrationTarget& target);
  // Per corner id its point on the bent board (mm, target frame): the printed point moved
  // along the board's normal by its offset, as the bundle fit's cost bends it.
  std::map<int, Eigen::Vector3d> CornerPoints(const CalibrationTarget& target) const;
  // The out-of-plane offset of a corner with that basis (mm).
  double OffsetMm(const Eigen::Vector2d& basis) const { return x_mm * basis.x() + y_mm * basis.y(); }
  // The whole out-of-plane offset of corner `id` with that basis (mm): paraboloid and relief.
  double CornerOffsetMm(int id, const Eigen::Vector2d& basis) const;
  bool IsZero() const;
};

// The warp over one board's extent, at any board point (x, y) mm: for rendering bent
// boards and their corners (calib/synthetic).
struct WarpedSurface {
  BoardWarp warp;
  Eigen::Vector2d low_mm = Eigen::Vector2d::Zero(), high_mm = Eigen::Vector2d::Zero();  // the corners' extent

  static WarpedSurface Of(const CalibrationTarget& target, const BoardWarp& warp);
  // (1 - u^2, 1 - v^2); 0 along an axis the corners do not span.
  Eigen::Vector2d BasisAt(double x_mm, double y_mm) const;
  double OffsetMm(double x_mm, double y_mm) const { return warp.OffsetMm(BasisAt(x_mm, y_mm)); }
  // d offset / d (x, y).
  Eigen::Vector2d Slope(double x_mm, double y_mm) const;
};

struct BoardWarpEstimate {
  BoardWarp warp;
  double std_x_mm = NAN, std_y_mm = NAN;  // from the fit's covariance (NaN without one)
  std::map<int, double> relief_std_mm;    // per corner id, when the relief was fitted
};

}  // namespace omnical
