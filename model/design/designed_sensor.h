// A mirror designed by the reflection ODE (model/design/mirror_design_ode.h) as a sensor every
// other subcommand takes: the profile becomes a tabulated mirror, the design's pinhole the
// lens, and the imager a square image whose centre the axis meets. Also the check of the
// design through that sensor: its rays, traced by omnical's own reflection code (not by
// the ODE), against the imaging law on cylinders at any distance (the seed's Figs. 9, 10
// and 14).
#pragma once

#include <string>
#include <vector>

#include "model/design/mirror_design_ode.h"
#include "model/sensor.h"

namespace omnical {

// The field's end (rho_end) images at 0.49 image widths from the centre: the pixel pitch
// (mm) is rho_end / (0.49 image_size_px). table_path is the CSV the sensor file names.
Sensor SensorFromOdeDesign(const OdeDesignSpec& spec, const OdeDesign& design, int image_size_px, const std::string& table_path);
double PixelPitchMm(const OdeDesign& design, int image_size_px);

// h(rho) on a cylinder of radius distance_mm, traced through the sensor: the ray of the
// pixel at image radius rho (mm, along +u from the centre) meets the cylinder at height h
// (mm, Gächter's frame: above the image plane). NaN where the ray fails or misses.
double TracedHeightMm(const Sensor& sensor, const OdeDesignSpec& spec, double pitch_mm, double rho_mm, double distance_mm);

// The seed's Fig. 10 / 14 ratio on intervals of rho: the traced increment of h over the
// law's own increment, divided by distance / d (so 1 means "the law, scaled"). One value per
// interval [rho_i, rho_i+1]; rho_mm holds the interval midpoints.
struct LawRatioCurve {
  double distance_mm = 0.0;
  std::vector<double> rho_mm, ratio;
};
LawRatioCurve TraceLawRatio(const Sensor& sensor, const OdeDesignSpec& spec, double pitch_mm, double distance_mm,
                            double rho_from_mm, double rho_to_mm, int intervals);

}  // namespace omnical
