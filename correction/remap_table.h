// Remap tables: for every pixel of a virtual screen, the omni-image pixel to sample. The
// output pixel's direction from V0 meets the object surface at a 3-D point whose exact
// (non-central) projection is the table entry, so the table is exact for objects on that
// surface and off by the seed's Eq. 23 error elsewhere.
//
// Speed: an axial sensor with a rotationally symmetric surface and a panorama or lonlat
// screen has one projection per row up to a rotation: the row is projected at four
// azimuths and every column follows as u = cu + au cos(phi), v = cv + av sin(phi) (exact
// for the lens models, which scale x and y separately about a centre; tested against the
// per-pixel path to 1e-6 px). Everything else (tilted or decentred sensors, perspective
// and equiangular screens, planes) is interpolated between exact nodes about
// kNodeSpacingDeg apart, checked cell by cell (model/grid_table.h): below 0.01 px
// everywhere on every shipped misaligned sensor, screen and surface (tests/remap_test.cc).
#pragma once

#include <vector>

#include "correction/object_surface.h"
#include "correction/virtual_screen.h"
#include "model/grid_table.h"
#include "model/progress.h"
#include "model/sensor.h"

namespace omnical {

struct RemapTable {
  int width = 0, height = 0;
  // Row-major omni-image pixel (centre of pixel (0, 0) at (0, 0)); -1 where the output
  // pixel sees no mirror (cv::remap then fills it with the border value).
  std::vector<float> map_x, map_y;
  long valid_pixels = 0;
  bool used_axial_symmetry = false;
  // Interpolated grid (0 when not used): its step, the valid pixels projected one by one
  // (in cells that failed the check or touch the field's edge), and the worst check (px).
  int interpolation_step_px = 0;
  long exact_pixels = 0;
  double worst_cell_check_px = 0.0;
};

struct RemapSettings {
  VirtualScreen screen;
  ObjectSurface surface;
  double v0_mm = 0.0;  // V0 as z on the mirror axis, mirror frame
  int threads = 1;
  bool allow_shortcuts = true;  // false: per-pixel projection everywhere (the reference)
  // Grid step of the interpolated path; 0: nodes about kNodeSpacingDeg apart.
  int interpolation_step_px = 0;
};

// "Distant" for an infinity surface: 1e7 rim radii from V0, where the viewpoint spread
// (mm) is far below 1e-6 px.
double InfinityDistanceMm(const Sensor& sensor);

// The object point (mirror frame) of an output point, false where there is none.
bool RemapObjectPoint(const Sensor& sensor, const RemapSettings& settings, double col, double row,
                      Eigen::Vector3d* point_in_mirror);

// Reports stage "remap table", one step per output row (from any thread, serialised);
// throws Cancelled when the callback returns false.
RemapTable BuildRemapTable(const Sensor& sensor, const RemapSettings& settings,
                           const ProgressCallback& progress = nullptr);

}  // namespace omnical
