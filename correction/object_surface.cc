#include "correction/object_surface.h"

#include <cmath>
#include <utility>

namespace omnical {

const char* SurfaceKindName(ObjectSurface::Kind kind) {
  switch (kind) {
    case ObjectSurface::Kind::kInfinity: return "infinity";
    case ObjectSurface::Kind::kSphere: return "sphere";
    case ObjectSurface::Kind::kCylinder: return "cylinder";
    case ObjectSurface::Kind::kPlane: return "plane";
  }
  return "?";
}

std::optional<ObjectSurface::Kind> ParseSurfaceKind(const std::string& name) {
  for (auto kind : {ObjectSurface::Kind::kInfinity, ObjectSurface::Kind::kSphere, ObjectSurface::Kind::kCylinder,
                    ObjectSurface::Kind::kPlane})
    if (name == SurfaceKindName(kind)) return kind;
  return std::nullopt;
}

std::string ObjectSurface::Check() const {
  if (kind == Kind::kInfinity) return "";
  // Only finite here: maps.json files written before the option bound
  // (model/object_distance.h) may hold farther distances, and still load.
  if (!(std::isfinite(distance_mm) && distance_mm > 0.0))
    return "distance_mm: " + std::to_string(distance_mm) + " (must be a finite distance > 0)";
  if (kind == Kind::kPlane && !(plane_normal.allFinite() && plane_normal.norm() > 1e-12)) return "plane_normal: zero or not finite";
  return "";
}

bool ObjectSurface::PointAlong(const Eigen::Vector3d& viewpoint, const Eigen::Vector3d& direction, double far_mm,
                               Eigen::Vector3d* point) const {
  double t = 0.0;
  switch (kind) {
    case Kind::kInfinity: t = far_mm; break;
    case Kind::kSphere: t = distance_mm; break;
    case Kind::kCylinder: {
      const double horizontal = std::hypot(direction.x(), direction.y());
      if (horizontal < 1e-12) return false;
      t = distance_mm / horizontal;  // V0 is on the axis
      break;
    }
    case Kind::kPlane: {
      const double along = direction.dot(plane_normal.normalized());
      if (!(along > 1e-12)) return false;
      t = distance_mm / along;
      break;
    }
  }
  *point = viewpoint + t * direction;
  return true;
}

bool ObjectSurface::IntersectRay(const Eigen::Vector3d& viewpoint, const Eigen::Vector3d& origin,
                                 const Eigen::Vector3d& direction, double far_mm, Eigen::Vector3d* point) const {
  // Smallest t > 0 of a t^2 + b t + c = 0.
  auto nearest_root = [](double a, double b, double c, double* t) {
    if (std::abs(a) < 1e-300) return false;
    const double discriminant = b * b - 4.0 * a * c;
    if (discriminant < 0.0) return false;
    const double q = -0.5 * (b + std::copysign(std::sqrt(discriminant), b));
    double t1 = q / a, t2 = q != 0.0 ? c / q : t1;
    if (t1 > t2) std::swap(t1, t2);
    *t = t1 > 0.0 ? t1 : t2;
    return *t > 0.0;
  };
  const Eigen::Vector3d from_viewpoint = origin - viewpoint;
  double t = 0.0;
  switch (kind) {
    case Kind::kInfinity:
      *point = viewpoint + far_mm * direction;
      return true;
    case Kind::kSphere:
      if (!nearest_root(direction.squaredNorm(), 2.0 * from_viewpoint.dot(direction),
                        from_viewpoint.squaredNorm() - distance_mm * distance_mm, &t))
        return false;
      break;
    case Kind::kCylinder:
      if (!nearest_root(direction.head<2>().squaredNorm(), 2.0 * origin.head<2>().dot(direction.head<2>()),
                        origin.head<2>().squaredNorm() - distance_mm * distance_mm, &t))
        return false;
      break;
    case Kind::kPlane: {
      const Eigen::Vector3d normal = plane_normal.normalized();
      const double along = direction.dot(normal);
      if (std::abs(along) < 1e-15) return false;
      t = (distance_mm - from_viewpoint.dot(normal)) / along;
      if (!(t > 0.0)) return false;
      break;
    }
  }
  *point = origin + t * direction;
  return true;
}

}  // namespace omnical
