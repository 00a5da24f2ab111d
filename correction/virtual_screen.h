// The virtual screen of the seed paper's image processing (Ohte & Tsuzuki Sec. 4): an
// output image whose every pixel is a viewing direction from the virtual projector's
// viewpoint V0. Directions are in the mirror frame (z along the mirror axis, from the lens
// towards the mirror), described by the seed's Omega (from the -z axis, i.e. from the
// camera) and the azimuth phi about z:
//   d(Omega, phi) = (sin Omega cos phi, sin Omega sin phi, -cos Omega).
// Elevation is Omega - 90 deg: positive towards the mirror's side of the horizon (up, for
// a camera looking up at a mirror above it).
//
// Output pixel (col, row), centre of pixel (0, 0) at (0, 0), W x H:
//  - panorama (cylindrical): phi = phi0 - 360 deg (col + 0.5) / W;
//      tan(elevation) linear in row: tan(e_top) at row -0.5, tan(e_bottom) at row H - 0.5.
//  - lonlat (equirectangular): phi as the panorama; elevation linear in row, e_top at
//      row -0.5, e_bottom at row H - 0.5.
//  - perspective: a pinhole looking along (pan, tilt) = (phi, elevation) of its axis,
//      rolled by roll about it; f = (W / 2) / tan(hfov / 2), centre ((W - 1) / 2,
//      (H - 1) / 2); d = forward + ((col - cx) right + (row - cy) down) / f with
//      right = forward x z (normalised), down = forward x right, then rolled.
//  - equiangular (the seed's "compensated circular image"): radius from the centre
//      ((W - 1) / 2, (H - 1) / 2) proportional to Omega, Omega_max at W / 2; the angle
//      about the centre is phi, as in the omni image (u right = +x, v down = +y).
// Columns run to decreasing phi in panoramas and to "right" in perspective views so that
// both read unmirrored when the camera looks up at the mirror.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

namespace omnical {

struct VirtualScreen {
  enum class Type { kPanorama, kLonLat, kPerspective, kEquiangular } type = Type::kPanorama;
  int width_px = 0, height_px = 0;
  // panorama, lonlat
  double azimuth0_deg = 0.0;  // phi of column -0.5 (the left edge)
  double elevation_top_deg = 30.0, elevation_bottom_deg = -30.0;
  // perspective
  double pan_deg = 0.0, tilt_deg = 0.0, roll_deg = 0.0, hfov_deg = 60.0;
  // equiangular
  double omega_max_deg = 120.0;

  // "field: problem" for an unusable geometry, empty if fine.
  std::string Check() const;

  // Unit viewing direction (mirror frame) of an output point; false where the view has
  // none (outside an equiangular disc).
  bool Direction(double col, double row, Eigen::Vector3d* direction) const;
  // The output point where a direction (any length, mirror frame) appears; false if it
  // does not (behind a perspective view, outside the elevation range's tan domain).
  bool PixelOf(const Eigen::Vector3d& direction, Eigen::Vector2d* pixel) const;

  // The pinhole of a perspective view: focal length (px), principal point, and the
  // rotation whose columns are right, down, forward (mirror frame).
  double FocalPx() const;
  Eigen::Matrix3d MirrorFromView() const;
};

const char* ScreenTypeName(VirtualScreen::Type type);
std::optional<VirtualScreen::Type> ParseScreenType(const std::string& name);

}  // namespace omnical
