#include "calib/board_warp.h"

#include <algorithm>

namespace omnical {

std::map<int, Eigen::Vector2d> BoardWarp::Basis(const CalibrationTarget& target) {
  Eigen::Vector2d low = Eigen::Vector2d::Constant(HUGE_VAL), high = Eigen::Vector2d::Constant(-HUGE_VAL);
  for (const TargetCorner& c : target.corners()) {
    low = low.cwiseMin(c.point_in_target.head<2>());
    high = high.cwiseMax(c.point_in_target.head<2>());
  }
  std::map<int, Eigen::Vector2d> basis;
  for (const TargetCorner& c : target.corners()) {
    Eigen::Vector2d unit = Eigen::Vector2d::Zero();  // a board one corner wide along an axis cannot bend along it
    for (int k = 0; k < 2; ++k)
      if (high[k] > low[k]) unit[k] = 2.0 * (c.point_in_target[k] - low[k]) / (high[k] - low[k]) - 1.0;
    basis[c.id] = Eigen::Vector2d(high.x() > low.x() ? 1.0 - unit.x() * unit.x() : 0.0,
                                  high.y() > low.y() ? 1.0 - unit.y() * unit.y() : 0.0);
  }
  return basis;
}

}  // namespace omnical
