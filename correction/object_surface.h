// Where the objects of a remap table are assumed to be. A non-central sensor images a
// direction from V0 at a pixel that depends on how far along it the object is (seed
// Sec. 4.2): at infinity (what central tools assume), on a sphere of radius D around V0,
// on a cylinder of radius D about the mirror axis, or on a plane D from V0 with a given
// normal. All in the mirror frame.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

namespace omnical {

struct ObjectSurface {
  enum class Kind { kInfinity, kSphere, kCylinder, kPlane } kind = Kind::kInfinity;
  double distance_mm = 0.0;                                 // D
  Eigen::Vector3d plane_normal = -Eigen::Vector3d::UnitZ();  // plane: unit, pointing from V0 to the plane

  // "field: problem" for an unusable surface (D <= 0 or not finite, a zero normal), else empty.
  std::string Check() const;

  // The object point seen from viewpoint (mirror frame) along unit direction; far_mm
  // stands for infinity. False where the direction never meets the surface (parallel
  // to a cylinder's axis, away from a plane).
  bool PointAlong(const Eigen::Vector3d& viewpoint, const Eigen::Vector3d& direction, double far_mm,
                  Eigen::Vector3d* point) const;
  // Where a sensor ray (origin, unit direction; mirror frame) meets the surface, the
  // nearest crossing ahead of its origin; infinity: viewpoint + far_mm * direction. False
  // if it never does.
  bool IntersectRay(const Eigen::Vector3d& viewpoint, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                    double far_mm, Eigen::Vector3d* point) const;
  // Rotationally symmetric about the mirror axis (with V0 on it)?
  bool IsAxiallySymmetric() const { return kind != Kind::kPlane; }
};

const char* SurfaceKindName(ObjectSurface::Kind kind);
std::optional<ObjectSurface::Kind> ParseSurfaceKind(const std::string& name);

}  // namespace omnical
