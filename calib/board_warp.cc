#include "calib/board_warp.h"

#include <algorithm>

namespace omnical {

WarpedSurface WarpedSurface::Of(const CalibrationTarget& target, const BoardWarp& warp) {
  WarpedSurface surface;
  surface.warp = warp;
  surface.low_mm = Eigen::Vector2d::Constant(HUGE_VAL);
  surface.high_mm = Eigen::Vector2d::Constant(-HUGE_VAL);
  for (const TargetCorner& c : target.corners()) {
    surface.low_mm = surface.low_mm.cwiseMin(c.point_in_target.head<2>());
    surface.high_mm = surface.high_mm.cwiseMax(c.point_in_target.head<2>());
  }
  if (target.corners().empty()) surface.low_mm = surface.high_mm = Eigen::Vector2d::Zero();
  return surface;
}

Eigen::Vector2d WarpedSurface::BasisAt(double x_mm, double y_mm) const {
  const Eigen::Vector2d point(x_mm, y_mm);
  Eigen::Vector2d basis = Eigen::Vector2d::Zero();  // a board one corner wide along an axis cannot bend along it
  for (int k = 0; k < 2; ++k)
    if (high_mm[k] > low_mm[k]) {
      const double unit = 2.0 * (point[k] - low_mm[k]) / (high_mm[k] - low_mm[k]) - 1.0;
      basis[k] = 1.0 - unit * unit;
    }
  return basis;
}

Eigen::Vector2d WarpedSurface::Slope(double x_mm, double y_mm) const {
  const Eigen::Vector2d point(x_mm, y_mm);
  const double deflection[2] = {warp.x_mm, warp.y_mm};
  Eigen::Vector2d slope = Eigen::Vector2d::Zero();
  for (int k = 0; k < 2; ++k)
    if (high_mm[k] > low_mm[k]) {
      const double span = high_mm[k] - low_mm[k];
      const double unit = 2.0 * (point[k] - low_mm[k]) / span - 1.0;
      slope[k] = deflection[k] * -2.0 * unit * 2.0 / span;
    }
  return slope;
}

std::map<int, Eigen::Vector2d> BoardWarp::Basis(const CalibrationTarget& target) {
  const WarpedSurface surface = WarpedSurface::Of(target, BoardWarp());
  std::map<int, Eigen::Vector2d> basis;
  for (const TargetCorner& c : target.corners()) basis[c.id] = surface.BasisAt(c.point_in_target.x(), c.point_in_target.y());
  return basis;
}

std::map<int, Eigen::Vector3d> BoardWarp::CornerPoints(const CalibrationTarget& target) const {
  std::map<int, Eigen::Vector3d> points;
  for (const TargetCorner& c : target.corners()) points[c.id] = c.point_in_target;
  if (!IsZero())
    for (const auto& [id, basis] : Basis(target)) points[id].z() += CornerOffsetMm(id, basis);
  return points;
}

double BoardWarp::CornerOffsetMm(int id, const Eigen::Vector2d& basis) const {
  const auto relief = relief_mm.find(id);
  return OffsetMm(basis) + (relief == relief_mm.end() ? 0.0 : relief->second);
}

bool BoardWarp::IsZero() const {
  return x_mm == 0.0 && y_mm == 0.0 &&
         std::all_of(relief_mm.begin(), relief_mm.end(), [](const auto& entry) { return entry.second == 0.0; });
}

}  // namespace omnical
