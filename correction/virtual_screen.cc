#include "correction/virtual_screen.h"

#include <Eigen/Geometry>

#include <cmath>

namespace omnical {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRad = kPi / 180.0;

Eigen::Vector3d FromOmegaAzimuth(double omega_rad, double azimuth_rad) {
  return {std::sin(omega_rad) * std::cos(azimuth_rad), std::sin(omega_rad) * std::sin(azimuth_rad), -std::cos(omega_rad)};
}

// The phi of a panorama column and back; phi is wrapped into the 360-degree span that
// starts at azimuth0 and runs down.
double ColumnAzimuthRad(const VirtualScreen& s, double col) {
  return (s.azimuth0_deg - 360.0 * (col + 0.5) / s.width_px) * kRad;
}
double AzimuthColumn(const VirtualScreen& s, double azimuth_rad) {
  double turns = (s.azimuth0_deg * kRad - azimuth_rad) / (2.0 * kPi);
  turns -= std::floor(turns);
  return turns * s.width_px - 0.5;
}

}  // namespace

const char* ScreenTypeName(VirtualScreen::Type type) {
  switch (type) {
    case VirtualScreen::Type::kPanorama: return "panorama";
    case VirtualScreen::Type::kLonLat: return "lonlat";
    case VirtualScreen::Type::kPerspective: return "perspective";
    case VirtualScreen::Type::kEquiangular: return "equiangular";
  }
  return "?";
}

std::optional<VirtualScreen::Type> ParseScreenType(const std::string& name) {
  for (auto type : {VirtualScreen::Type::kPanorama, VirtualScreen::Type::kLonLat, VirtualScreen::Type::kPerspective,
                    VirtualScreen::Type::kEquiangular})
    if (name == ScreenTypeName(type)) return type;
  return std::nullopt;
}

std::string VirtualScreen::Check() const {
  auto finite = [](double x) { return std::isfinite(x); };
  if (width_px < 2 || height_px < 2 || width_px > 20000 || height_px > 20000)
    return "size: " + std::to_string(width_px) + " x " + std::to_string(height_px) + " px (each side 2..20000)";
  switch (type) {
    case Type::kPanorama:
    case Type::kLonLat: {
      if (!finite(azimuth0_deg) || !finite(elevation_top_deg) || !finite(elevation_bottom_deg))
        return "azimuth0_deg/elevation_deg: not finite";
      const double limit = type == Type::kPanorama ? 89.0 : 90.0;  // a cylinder cannot reach the poles
      if (!(elevation_top_deg > elevation_bottom_deg) || elevation_top_deg > limit || elevation_bottom_deg < -limit)
        return "elevation_deg: top " + std::to_string(elevation_top_deg) + " deg must be above bottom " +
               std::to_string(elevation_bottom_deg) + " deg, both within +-" + std::to_string(int(limit)) + " deg";
      return "";
    }
    case Type::kPerspective:
      if (!finite(pan_deg) || !finite(tilt_deg) || !finite(roll_deg)) return "pan_deg/tilt_deg/roll_deg: not finite";
      if (!(hfov_deg > 0.0 && hfov_deg < 170.0)) return "hfov_deg: " + std::to_string(hfov_deg) + " deg (0 < hfov < 170)";
      if (std::abs(tilt_deg) > 90.0) return "tilt_deg: " + std::to_string(tilt_deg) + " deg (within +-90)";
      return "";
    case Type::kEquiangular:
      if (!(omega_max_deg > 0.0 && omega_max_deg <= 180.0)) return "omega_max_deg: " + std::to_string(omega_max_deg) + " deg (0..180)";
      return "";
  }
  return "type: unknown";
}

double VirtualScreen::FocalPx() const { return 0.5 * width_px / std::tan(0.5 * hfov_deg * kRad); }

Eigen::Matrix3d VirtualScreen::MirrorFromView() const {
  const Eigen::Vector3d forward = FromOmegaAzimuth((90.0 + tilt_deg) * kRad, pan_deg * kRad);
  // At tilt +-90 the forward axis is the mirror axis: "right" then follows the pan.
  Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ());
  if (right.norm() < 1e-9) right = FromOmegaAzimuth(90.0 * kRad, (pan_deg - 90.0) * kRad);
  right.normalize();
  const Eigen::Vector3d down = forward.cross(right);  // right x down = forward: a proper rotation
  Eigen::Matrix3d rotation;
  rotation << right, down, forward;
  return rotation * Eigen::AngleAxisd(roll_deg * kRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

bool VirtualScreen::Direction(double col, double row, Eigen::Vector3d* direction) const {
  switch (type) {
    case Type::kPanorama: {
      const double t_top = std::tan(elevation_top_deg * kRad), t_bottom = std::tan(elevation_bottom_deg * kRad);
      const double t = t_top + (t_bottom - t_top) * (row + 0.5) / height_px;
      const double azimuth = ColumnAzimuthRad(*this, col);
      *direction = Eigen::Vector3d(std::cos(azimuth), std::sin(azimuth), t).normalized();
      return true;
    }
    case Type::kLonLat: {
      const double e = elevation_top_deg + (elevation_bottom_deg - elevation_top_deg) * (row + 0.5) / height_px;
      *direction = FromOmegaAzimuth((90.0 + e) * kRad, ColumnAzimuthRad(*this, col));
      return true;
    }
    case Type::kPerspective: {
      const double f = FocalPx();
      const Eigen::Vector3d in_view((col - 0.5 * (width_px - 1)) / f, (row - 0.5 * (height_px - 1)) / f, 1.0);
      *direction = (MirrorFromView() * in_view).normalized();
      return true;
    }
    case Type::kEquiangular: {
      const double x = col - 0.5 * (width_px - 1), y = row - 0.5 * (height_px - 1);
      const double omega = std::hypot(x, y) / (0.5 * width_px) * omega_max_deg * kRad;
      if (omega > kPi) return false;
      *direction = FromOmegaAzimuth(omega, std::atan2(y, x));
      return true;
    }
  }
  return false;
}

bool VirtualScreen::PixelOf(const Eigen::Vector3d& direction, Eigen::Vector2d* pixel) const {
  const double horizontal = std::hypot(direction.x(), direction.y());
  switch (type) {
    case Type::kPanorama: {
      if (horizontal <= 0.0) return false;
      const double t_top = std::tan(elevation_top_deg * kRad), t_bottom = std::tan(elevation_bottom_deg * kRad);
      const double t = direction.z() / horizontal;
      *pixel = Eigen::Vector2d(AzimuthColumn(*this, std::atan2(direction.y(), direction.x())),
                               (t - t_top) / (t_bottom - t_top) * height_px - 0.5);
      return true;
    }
    case Type::kLonLat: {
      if (direction.norm() <= 0.0) return false;
      const double e = std::atan2(direction.z(), horizontal) / kRad;
      *pixel = Eigen::Vector2d(AzimuthColumn(*this, std::atan2(direction.y(), direction.x())),
                               (e - elevation_top_deg) / (elevation_bottom_deg - elevation_top_deg) * height_px - 0.5);
      return true;
    }
    case Type::kPerspective: {
      const Eigen::Vector3d in_view = MirrorFromView().transpose() * direction;
      if (!(in_view.z() > 0.0)) return false;
      const double f = FocalPx();
      *pixel = Eigen::Vector2d(f * in_view.x() / in_view.z() + 0.5 * (width_px - 1),
                               f * in_view.y() / in_view.z() + 0.5 * (height_px - 1));
      return true;
    }
    case Type::kEquiangular: {
      if (direction.norm() <= 0.0) return false;
      const double omega = std::atan2(horizontal, -direction.z());
      const double radius = omega / (omega_max_deg * kRad) * 0.5 * width_px;
      const double azimuth = std::atan2(direction.y(), direction.x());
      *pixel = Eigen::Vector2d(0.5 * (width_px - 1) + radius * std::cos(azimuth),
                               0.5 * (height_px - 1) + radius * std::sin(azimuth));
      return true;
    }
  }
  return false;
}

}  // namespace omnical
