#include "calib/board_size_screen.h"

#include <cmath>

#include "model/parallel_rows.h"

namespace omnical {

BoardSizeScreen ScreenBoardSizes(const Sensor& start, const CalibrationTarget& target, const DetectionSet& detections,
                                 const FitResult& fit, const FitOptions& fit_options,
                                 const BoardSizeScreenOptions& options) {
  BoardSizeScreen screen;
  const size_t views = detections.images.size();
  screen.checks.resize(views);
  if (!fit.sensor) return screen;
  // Four small fits per view, independent: a third of `calibrate --detections` on the
  // rendered misaligned set when run one after another.
  ParallelRows(static_cast<int>(views), options.threads, [&](int v) {
    if (fit.view_left_out[v].empty())
      screen.checks[v] = CheckBoardScale(*fit.sensor, target, detections.images[v], fit.poses[v], fit.sigma_px,
                                         options.scale, WarpOf(fit, fit_options));
  });
  double strongest = options.scale.min_chi2;
  for (size_t v = 0; v < views; ++v) {
    const BoardScale& check = screen.checks[v];
    if (check.refused) {
      screen.refused.push_back(v);
    } else if (fit.view_left_out[v].empty() && std::abs(std::log(check.best_scale)) > std::log(options.suspect_ratio) &&
               check.chi2_gain > strongest) {
      strongest = check.chi2_gain;
      screen.suspect = static_cast<int>(v);
    }
  }
  if (!screen.refused.empty()) screen.suspect = -1;  // the caller refits without them and screens again
  if (screen.suspect < 0) return screen;
  const size_t suspect = static_cast<size_t>(screen.suspect);
  DetectionSet others = detections;
  others.images.erase(others.images.begin() + suspect);
  std::vector<TargetPose> poses = fit.poses;
  poses.erase(poses.begin() + suspect);
  FitOptions quiet = fit_options;
  quiet.progress = nullptr;
  quiet.compute_covariance = false;
  const FitResult without = FitSensor(start, target, others, poses, quiet);
  if (!without.sensor) return screen;
  BoardScale check = CheckBoardScale(*without.sensor, target, detections.images[suspect], fit.poses[suspect],
                                     without.sigma_px, options.scale, WarpOf(without, fit_options));
  if (check.refused) {
    check.reason = "(through a fit without this view) " + check.reason;
    screen.checks[suspect] = check;
    screen.refused.push_back(suspect);
  }
  return screen;
}

}  // namespace omnical
