// The `characterize` job: the seed paper's evaluation of a sensor (Ohte & Tsuzuki Secs.
// 2-3 and appendix; model/optics.h): image-forming characteristics, viewpoints, virtual
// images, blur and depth of field over the mirror, with the lens of the blur analysis and
// the in-focus distance chosen here. No printing, no files: model/design/design_files.h
// writes characteristics.csv and summary.json, calib/report the figures (Figs. 4-9).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "model/optics.h"
#include "model/progress.h"
#include "model/sensor.h"

namespace omnical {

struct CharacterizeOptions {
  std::optional<double> lens_focal_mm;  // default: the sensor's own, fx x pixel size
  std::optional<double> focus_mm;       // in-focus distance L0; default: searched
  double f_number = 4.0;
  double pixel_um = 5.2;      // pixel size: the permissible circle of confusion
  double near_n = 5.0;        // near object distance for the virtual images, in mirror radii
  int samples = 540;          // mirror radii analysed
  ProgressCallback progress;  // stages "field", "focus", "azimuth curves"
  // "field: problem", else empty.
  std::string Check() const;
};

struct CharacterizeResult {
  std::string profile_name, lens_name;
  bool axial = true;  // false: analysed as the aligned counterpart, azimuth curves exact
  double rim_radius_mm = 0.0, m_mm = 0.0;
  int samples = 0;
  double pixel_um = 0.0, near_distance_mm = 0.0;
  std::vector<FieldSample> field;  // x = rim * i / samples, i = 1..samples
  BlurSettings lens;
  double focus_mm = 0.0;  // L0
  bool focus_searched = false;
  double depth_of_field_mm = 0.0;  // infinite beyond the hyperfocal distance
  double mean_blur_area_deg2 = 0.0;
  std::vector<BlurSpot> blur;  // per field sample, at focus_mm
  // Summary over the field.
  double viewpoint_min_mm = 0.0, viewpoint_max_mm = 0.0;  // Eq. 6's z_v
  double caustic_radial_mm = 0.0, caustic_axial_mm = 0.0;
  double max_astigmatism_mm = 0.0;  // max |L_t - L_s| of the far virtual images
  double worst_blur_px = 0.0;
  double dh_domega_min = 0.0, dh_domega_max = 0.0;  // px/deg
  double mean_solid_angle_per_pixel_deg2 = 0.0;
  // A tilted or decentred sensor only: the exact characteristic along azimuths 0, 90, 180
  // and 270 deg.
  std::vector<std::vector<AzimuthSample>> azimuth_curves;

  double rim_omega_deg() const;
  double rim_theta_deg() const;
  double viewpoint_spread_mm() const { return viewpoint_max_mm - viewpoint_min_mm; }
};

// Throws InputError "sensor: problem" when the rim images outside the image,
// "lens_focal_mm: problem" for an orthographic sensor without one, "field: problem" for
// options Check() refuses; Cancelled when progress says stop.
CharacterizeResult Characterize(const Sensor& sensor, const CharacterizeOptions& options);

}  // namespace omnical
