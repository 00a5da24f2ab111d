#include "correction/view_request.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <thread>

#include "correction/viewpoint_error.h"
#include "model/input_error.h"
#include "model/object_distance.h"

namespace omnical {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

std::string FieldMessage(const std::string& field, const std::string& problem) { return field + ": " + problem; }

// "WxH" -> (width, height); false if it is not that.
bool ParseSize(const std::string& text, int* width, int* height) {
  char x = 0;
  std::istringstream in(text);
  return (in >> *width >> x >> *height) && (x == 'x' || x == 'X') && in.eof();
}

}  // namespace

std::string ViewRequest::Check() const {
  if (!ParseScreenType(view)) return FieldMessage("view", "unknown view '" + view + "'");
  int width = 0, height = 0;
  if (!size.empty() && !ParseSize(size, &width, &height))
    return FieldMessage("size", "'" + size + "' is not WxH (e.g. 2048x512)");
  if (!elevation_deg.empty() && elevation_deg.size() != 2) return FieldMessage("elevation_deg", "give top and bottom");
  if (int(distance_mm.has_value()) + int(n.has_value()) + int(infinity) > 1)
    return FieldMessage(n ? "n" : "distance_mm", "give only one of distance_mm, n and infinity");
  if (!infinity) {
    if (!distance_mm && !n) return FieldMessage("distance_mm", "give the object distance (distance_mm or n) or infinity");
    const auto kind = ParseSurfaceKind(surface);
    if (!kind || *kind == ObjectSurface::Kind::kInfinity) return FieldMessage("surface", "unknown '" + surface + "'");
    const double distance = distance_mm ? *distance_mm : *n;
    if (!std::isfinite(distance) || distance <= 0.0) return FieldMessage(n ? "n" : "distance_mm", "the object distance must be > 0");
  }
  if (!plane_normal.empty()) {
    if (infinity || surface != "plane") return FieldMessage("plane_normal", "only for a plane surface");
    const bool finite = std::all_of(plane_normal.begin(), plane_normal.end(), [](double x) { return std::isfinite(x); });
    if (plane_normal.size() != 3 || !finite || Eigen::Vector3d(plane_normal[0], plane_normal[1], plane_normal[2]).norm() <= 0.0)
      return FieldMessage("plane_normal", "zero or not finite");
  }
  if (v0_mm)
    if (const std::string why = ViewpointProblem(*v0_mm); !why.empty()) return FieldMessage("v0_mm", why);
  if (threads < 0) return FieldMessage("threads", "must be >= 0");
  return "";
}

ResolvedView ResolveView(const Sensor& sensor, const ViewRequest& request) {
  if (const std::string why = request.Check(); !why.empty()) throw InputError(why);
  ResolvedView resolved;
  RemapSettings& settings = resolved.settings;
  VirtualScreen& screen = settings.screen;
  screen.type = *ParseScreenType(request.view);
  const double rim = sensor.rim_radius_mm();
  if (request.size.empty()) {
    const bool wide = screen.type == VirtualScreen::Type::kPanorama || screen.type == VirtualScreen::Type::kLonLat;
    screen.width_px = wide ? 2048 : screen.type == VirtualScreen::Type::kPerspective ? 800 : 1000;
    screen.height_px = wide ? 512 : screen.type == VirtualScreen::Type::kPerspective ? 600 : 1000;
  } else {
    ParseSize(request.size, &screen.width_px, &screen.height_px);
  }

  // Objects.
  ObjectSurface& surface = settings.surface;
  if (!request.infinity) {
    surface.kind = *ParseSurfaceKind(request.surface);
    surface.distance_mm = request.distance_mm ? *request.distance_mm : *request.n * rim;
    if (const std::string why = ObjectDistanceProblem(surface.distance_mm); !why.empty())
      throw InputError(FieldMessage(request.n ? "n" : "distance_mm", why));
  }
  if (!request.plane_normal.empty())
    surface.plane_normal =
        Eigen::Vector3d(request.plane_normal[0], request.plane_normal[1], request.plane_normal[2]).normalized();
  if (const std::string problem = surface.Check(); !problem.empty()) throw InputError(problem);

  // The field (aligned counterpart for a misaligned sensor): the default ranges and V0.
  const double reference_distance = ReferenceDistanceMm(sensor, surface);
  const std::vector<FieldSample> field = AnalyzeField(sensor, 360, reference_distance);
  double omega_min = HUGE_VAL, omega_max = 0.0;
  for (const FieldSample& f : field) omega_min = std::min(omega_min, f.ray.omega_rad), omega_max = std::max(omega_max, f.ray.omega_rad);
  omega_min /= kDeg, omega_max /= kDeg;
  settings.v0_mm = ResolveV0Mm(field, reference_distance, request.v0_mm);
  resolved.v0_searched = !request.v0_mm;

  screen.azimuth0_deg = request.azimuth0_deg;
  if (request.elevation_deg.size() == 2) {
    screen.elevation_top_deg = request.elevation_deg[0];
    screen.elevation_bottom_deg = request.elevation_deg[1];
  } else {
    screen.elevation_top_deg = std::min(89.0, omega_max - 90.0);
    screen.elevation_bottom_deg = std::max(-60.0, omega_min - 90.0);
  }
  screen.pan_deg = request.pan_deg, screen.tilt_deg = request.tilt_deg, screen.roll_deg = request.roll_deg;
  screen.hfov_deg = request.hfov_deg;
  screen.omega_max_deg = request.omega_max_deg ? *request.omega_max_deg : omega_max;
  if (const std::string problem = screen.Check(); !problem.empty()) throw InputError(problem);
  settings.allow_shortcuts = !request.per_pixel;
  settings.threads =
      request.threads > 0 ? request.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return resolved;
}

double ReferenceDistanceMm(const Sensor& sensor, const ObjectSurface& surface) {
  return surface.kind == ObjectSurface::Kind::kInfinity ? 1e4 * sensor.rim_radius_mm() : surface.distance_mm;
}

double ResolveV0Mm(const std::vector<FieldSample>& field, double reference_distance_mm, const std::optional<double>& given) {
  if (!given) return BestViewpointMm(field, reference_distance_mm);
  if (const std::string why = ViewpointProblem(*given); !why.empty()) throw InputError(FieldMessage("v0_mm", why));
  return *given;
}

}  // namespace omnical
