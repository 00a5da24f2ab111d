// Frames, units and status codes shared by every model type.
//
// Frame convention (COLMAP style): x_in_b = b_from_a * x_in_a.
//  - camera frame: OpenCV convention, origin at the lens centre (pinhole) or on the
//    optical axis in the lens plane (orthographic); x right, y down, z along the
//    optical axis towards the mirror. Lengths in mm.
//  - mirror frame: origin at the mirror vertex, z along the mirror axis pointing away
//    from the camera; the surface is z = f(r) with r the distance from the axis (mm).
//  - camera_from_mirror: point_in_camera = Ry(tilt_y) * Rx(tilt_x) * point_in_mirror
//                                          + (decenter_x, decenter_y, m).
//  - pixels: u = fx * x' + cx with x' the distorted normalised coordinate; the centre
//    of pixel (0, 0) is at u = v = 0, so an image spans [-0.5, W - 0.5].
#pragma once

#include <Eigen/Core>
#include <cstdint>

namespace omnical {

template <typename T>
using Vec2 = Eigen::Matrix<T, 2, 1>;
template <typename T>
using Vec3 = Eigen::Matrix<T, 3, 1>;
template <typename T>
using Mat3 = Eigen::Matrix<T, 3, 3>;

// Why a projection or unprojection has no answer. Returned, never thrown: these are
// ordinary outcomes in hot loops (most of a scene is not visible in the mirror).
enum class ProjectionStatus : std::uint8_t {
  kOk = 0,
  kOutsideMirror,     // the reflection point would lie beyond the mirror rim
  kBehindMirror,      // the point is on the far side of the mirror surface
  kOccludedByCamera,  // the ray from the mirror to the point hits the camera body
  kOutsideImage,      // the pixel falls outside the sensor's image
  kMissesMirror,      // (unprojection) the lens ray does not head towards the mirror
  kNoSolution,        // the solver did not converge (should not happen for convex mirrors)
  kInvalidInput,      // NaN or infinite input
};

// Stable lower-case names used in CSV and JSON output.
const char* StatusName(ProjectionStatus status);

}  // namespace omnical
