// Object distances the tools take, in mm (from the mirror's reference point or a view's
// centre): finite, > 0 and at most kMaxObjectDistanceMm, which stands for infinity where a
// tool has no option of its own for it (remap --infinity, export-central without a
// distance). A distance of 1e300 mm overflowed when squared and failed later with messages
// about other options.
#pragma once

#include <cmath>
#include <string>

namespace omnical {

// 100 km: calib's stand-in for infinity (calib/predicted_error.h) is this distance.
inline constexpr double kMaxObjectDistanceMm = 1e8;

// "" when `distance_mm` is a usable object distance, else why not (without a field name).
inline std::string ObjectDistanceProblem(double distance_mm) {
  if (!(std::isfinite(distance_mm) && distance_mm > 0.0)) return "the object distance must be > 0 and finite";
  if (distance_mm > kMaxObjectDistanceMm) return "the object distance must be at most 1e8 mm (100 km; 1e8 stands for infinity)";
  return "";
}

// A central viewpoint V0 on the mirror axis (mm from the vertex) lies near the mirror: a
// v0 of 1e300 mm gave maps of no finite pixel, reported as a 0 px error.
inline constexpr double kMaxViewpointOffsetMm = 1e6;
inline std::string ViewpointProblem(double v0_mm) {
  if (!std::isfinite(v0_mm)) return "not finite";
  if (std::abs(v0_mm) > kMaxViewpointOffsetMm) return "must lie within 1e6 mm of the mirror vertex";
  return "";
}

}  // namespace omnical
