// Pose of the mirror relative to the camera: lens-to-vertex distance m, axis tilt
// (two angles) and decenter (two offsets).
// point_in_camera = Ry(tilt_y) * Rx(tilt_x) * point_in_mirror + (decenter_x, decenter_y, m).
#pragma once

#include <cmath>

#include "model/scalar.h"
#include "model/types.h"

namespace omnical {

template <typename T>
struct MirrorPose {
  static constexpr int kNumParams = 5;
  static constexpr const char* kParamsInfo = "m_mm, tilt_x_rad, tilt_y_rad, decenter_x_mm, decenter_y_mm";
  T m_mm;
  T tilt_x_rad;
  T tilt_y_rad;
  T decenter_x_mm;
  T decenter_y_mm;

  bool IsUntilted() const {
    return ScalarPart(tilt_x_rad) == 0.0 && ScalarPart(tilt_y_rad) == 0.0;
  }
  bool IsCentred() const {
    return ScalarPart(decenter_x_mm) == 0.0 && ScalarPart(decenter_y_mm) == 0.0;
  }

  Mat3<T> CameraFromMirrorRotation() const {
    using std::cos;
    using std::sin;
    const T cx = cos(tilt_x_rad), sx = sin(tilt_x_rad);
    const T cy = cos(tilt_y_rad), sy = sin(tilt_y_rad);
    Mat3<T> rotation;
    // Ry(ty) * Rx(tx)
    rotation << cy, sy * sx, sy * cx,
                T(0.0), cx, -sx,
                -sy, cy * sx, cy * cx;
    return rotation;
  }
  Vec3<T> CameraFromMirrorTranslation() const { return Vec3<T>(decenter_x_mm, decenter_y_mm, m_mm); }

  template <typename U>
  MirrorPose<U> Cast() const {
    return {CastScalar<U>(m_mm), CastScalar<U>(tilt_x_rad), CastScalar<U>(tilt_y_rad),
            CastScalar<U>(decenter_x_mm), CastScalar<U>(decenter_y_mm)};
  }
  static MirrorPose FromParams(const T* p) { return {p[0], p[1], p[2], p[3], p[4]}; }
  void ToParams(T* p) const {
    p[0] = m_mm; p[1] = tilt_x_rad; p[2] = tilt_y_rad; p[3] = decenter_x_mm; p[4] = decenter_y_mm;
  }
};

}  // namespace omnical
