// The optics analysis of the seed paper (Ohte & Tsuzuki 2012) for an axial sensor:
// image-forming characteristics (Eqs. 7-12), viewpoint distribution (Eq. 6), tangential
// and sagittal virtual images (Eqs. 13-20), blur spots and depth of field (appendix,
// Eqs. 24-37, with the SEED-NOTES corrections: Eq. 37 uses L_s).
//
// Everything is evaluated along the mirror's cross-section, sampled by the radius x of
// the reflection point (0 < x <= rim); a tilted or decentred sensor is analysed through
// its aligned counterpart (see AlignedCounterpart).
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "model/ray_quantities.h"
#include "model/sensor.h"

namespace omnical {

// Lens and imager of the blur / depth-of-field analysis (appendix of the seed paper).
struct BlurSettings {
  double lens_focal_mm = 0.0;  // f
  double f_number = 0.0;       // F = f / D
  double pixel_mm = 0.0;       // delta, the permissible circle of confusion (one pixel)
};

// A virtual image point of the mirror (Eqs. 14-16 or 18-20), mirror frame.
struct VirtualImage {
  double distance_mm;       // q: from the reflection point, behind the mirror along the lens ray
  double x_mm, z_mm;        // Q
  double lens_distance_mm;  // L = m + z_q, its distance from the lens along the axis (Eqs. 34-35)
};

struct FieldSample {
  AxialRayQuantities ray;     // Eqs. 1-6
  double h_px;                // radial image height (Eq. 7, through the lens model incl. distortion)
  double dh_domega_px_per_rad;  // Eq. 8
  double delta_h_px;          // Eq. 9: radial size of a 1 x 1 deg object
  double delta_w_px;          // Eq. 10: its circumferential size
  double delta_s_px2;         // Eq. 11: its area
  double aspect_ratio;        // Eq. 12: delta_w / delta_h
  double tangential_curvature_per_mm;  // 1 / R_t (Eq. 13)
  double sagittal_curvature_per_mm;    // 1 / R_s (Eq. 17)
  VirtualImage tangential_far, sagittal_far;    // object at infinity
  VirtualImage tangential_near, sagittal_near;  // object at near_distance_mm from P
  // The caustic: the envelope of the object rays in the cross-section, where neighbouring
  // rays meet (behind the mirror for a convex one). A single viewpoint makes it a point.
  double caustic_x_mm, caustic_z_mm;
};

// Samples the field at n radii x_i = rim * i / n, i = 1..n. Throws std::invalid_argument
// if the sensor's profile has no defined curvature there (never for shipped profiles).
std::vector<FieldSample> AnalyzeField(const Sensor& sensor, int samples, double near_distance_mm);

// The sensor with tilt and decenter set to zero (the analysis is axial).
Sensor AlignedCounterpart(const Sensor& sensor);

// Blur spot of an object imaged at lens distance L when the lens is focused at L0:
// Eq. 28 (exact thin lens, not the L0 >> f approximation of Eq. 29), in mm on the sensor.
// The sign says on which side of focus the image is.
double BlurDiameterMm(const BlurSettings& lens, double lens_distance_mm, double focus_distance_mm);

// Eq. 32: the exact depth of field L_f - L_r at focus distance L0 (infinite beyond the
// hyperfocal distance).
double DepthOfFieldMm(const BlurSettings& lens, double focus_distance_mm);

struct BlurSpot {
  double tangential_px, sagittal_px;    // signed, Eq. 28 / delta
  double tangential_deg, sagittal_deg;  // in object space, Eqs. 36-37 (absolute values)
  double area_deg2;                     // tangential_deg x sagittal_deg
};

// Blur of the far (infinity) virtual images of a field sample. The object-space sizes
// floor each direction at one pixel: a blur below a pixel cannot be seen (seed Sec. 3.3).
BlurSpot BlurAt(const FieldSample& sample, const BlurSettings& lens, double focus_distance_mm);

// The in-focus distance L0 that minimises the overall blur: the solid-angle weighted
// mean (weight sin(Omega) dOmega) of the blur-spot area in square degrees over the field.
// Searched over the range of the virtual images' lens distances (coarse scan, then Brent).
// Returns the mean area at the optimum too.
double BestFocusDistanceMm(const std::vector<FieldSample>& field, const BlurSettings& lens,
                           double* mean_area_deg2 = nullptr);
double MeanBlurAreaDeg2(const std::vector<FieldSample>& field, const BlurSettings& lens, double focus_distance_mm);

// For a tilted or decentred sensor, the exact characteristic along one azimuth of the
// mirror: the mirror point at radius x_i along that azimuth, its pixel, the exact ray of
// that pixel (Omega from the mirror's -z axis) and h = the pixel's distance from the
// vertex's pixel.
struct AzimuthSample {
  double x_mm, omega_rad, h_px;
};
std::vector<AzimuthSample> ExactAzimuthCurve(const Sensor& sensor, double azimuth_rad, int samples);

// Empty when the whole mirror rim images inside the image; else which part does not.
std::string RimOutsideImage(const Sensor& sensor);

// Mean solid angle per pixel over the field (seed Sec. 3.3): the solid angle between
// Omega = 0 and the rim's Omega, over the pixels of the image circle pi h_rim^2.
double MeanSolidAnglePerPixelDeg2(const std::vector<FieldSample>& field);

}  // namespace omnical
