#include "correction/remap_error_sweep.h"

#include <algorithm>
#include <cmath>

namespace omnical {

RemapErrorSweep SweepOf(SweepDistances preset, const RemapSettings& settings, double rim_mm) {
  RemapErrorSweep sweep;
  const int longest_side = std::max(settings.screen.width_px, settings.screen.height_px);
  if (preset == SweepDistances::kSummary) {
    sweep.n = {1.5, 2.0, 3.0, 5.0, 7.0, 10.0, 20.0, 40.0, 100.0};
    sweep.stride_px = std::max(1, longest_side / 96);
  } else {
    for (double n = 1.5; n < 200.0; n *= 1.25) sweep.n.push_back(n);
    for (double n : {2.0, 3.0, 5.0, 7.0, 10.0, 20.0, 40.0, 100.0}) sweep.n.push_back(n);
    if (settings.surface.kind != ObjectSurface::Kind::kInfinity) sweep.n.push_back(settings.surface.distance_mm / rim_mm);
    std::sort(sweep.n.begin(), sweep.n.end());
    sweep.n.erase(std::unique(sweep.n.begin(), sweep.n.end()), sweep.n.end());
    sweep.stride_px = std::max(1, longest_side / 128);
  }
  sweep.n.push_back(HUGE_VAL);
  return sweep;
}

std::vector<RemapErrorAtDistance> SweepRemapError(const Sensor& sensor, const RemapSettings& settings,
                                                  const RemapErrorSweep& sweep, const ProgressCallback& progress) {
  const double rim = sensor.rim_radius_mm();
  ProgressReporter reporter(progress, "remap error", static_cast<long>(sweep.n.size()));
  std::vector<RemapErrorAtDistance> errors;
  for (double n : sweep.n) {
    const double distance_mm = n * rim;  // +inf for infinity
    errors.push_back({n, distance_mm, RemapErrorAt(sensor, settings, ObjectAtDistance(settings.surface, distance_mm), sweep.stride_px)});
    reporter.Step();
  }
  return errors;
}

}  // namespace omnical
