// Mirror design by parameters (Ohte & Tsuzuki 2012, Sec. 3.1 and Table 1), solved with
// Ceres instead of the paper's trial and error: a profile family of the registry (every
// profile with a kRimSlopeParam, model/model_registry.h) whose rim ray has exactly the target Omega and Theta,
// and whose image follows a characteristic (equidistant, single viewpoint, constant aspect
// ratio, equal area) as closely as the family allows.
//
// Units are the paper's normalised ones (mirror radius M = 1 at the rim, lens principal
// point at (0, -m), SEED-NOTES "Conventions"); SensorFromFitDesign scales to mm. The two
// rim targets are not residuals: they are solved exactly for two of the parameters, so
// Ceres only moves the family's remaining freedom:
//   tan(beta_rim) = f'(1) with beta_rim = (Omega_rim - Theta_rim) / 2   (Eq. 4)
//   m = 1 / tan(Theta_rim) - f(1)                                          (Eq. 5)
// A sphere or paraboloid has no freedom left (A and m follow in closed form), a
// hyperboloid one (A), an n-term polynomial n - 1 (c2..cn): each profile's SolveRimSlope
// sets the one parameter the slope fixes.
#pragma once

#include <string>
#include <vector>

#include "model/progress.h"
#include "model/sensor.h"

namespace omnical {

// The image law each characteristic asks for, with h the image radius and h_rim the rim's:
//   equidistant      h / h_rim = Omega / Omega_rim            (Sec. 3.5)
//   constant aspect  h / h_rim = tan(Omega/2) / tan(Omega_rim/2)  (Eq. 12 equal to 1)
//   equal area       h / h_rim = sin(Omega/2) / sin(Omega_rim/2)  (Eq. 11 constant)
//   single viewpoint z_v = z + x / tan(Omega) the same for every ray (Eq. 6)
enum class ImageCharacteristic { kNone, kEquidistant, kSingleViewpoint, kConstantAspect, kEqualArea };

const char* CharacteristicName(ImageCharacteristic characteristic);

struct FitDesignSpec {
  std::string profile = "polynomial";  // one of DesignProfileNames() (model/model_registry.h)
  // The length of the profile's list of terms (polynomial: c1 x^2 + ... + cn x^2n, Table
  // 1's E-DI: 3); ignored by a profile without one.
  int terms = 3;
  double rim_omega_deg = 135.0;
  double rim_theta_deg = 12.0;
  ImageCharacteristic characteristic = ImageCharacteristic::kNone;
  int samples = 200;  // characteristic residuals at x = i / samples, i = 1..samples
  // "field: problem" when the targets cannot make a mirror, else empty.
  std::string Check() const;
};

struct FitDesign {
  std::string profile;
  // Normalised parameters as Table 1 prints them: sphere {A}; hyperboloid {A, B};
  // polynomial {c1, ..., cn} (the table's A, B, C for n = 3); any family: its fields' order.
  std::vector<double> params;
  std::vector<std::string> names;     // sensor-file keys (A, B, R, k) or terms (c1, a4)
  std::vector<std::string> mm_names;  // the same in mm: A_mm, c2_per_mm3, k, a4_per_mm3
  std::vector<int> length_powers;     // a parameter in mm is the normalised one x rim^p
  double m = 0.0;
  int free_params = 0;
  int iterations = 0;
  double final_cost = 0.0;  // Ceres' 1/2 sum of squared residuals (normalised h or z_v)
  std::string solver_report;  // Ceres' brief report, "closed form" for the sphere
};

// Throws InputError naming the cause when the targets are outside the family's reach,
// Ceres does not converge, or the fitted mirror folds the image (Omega or the image
// height stops increasing with x, "at x = ... (mirror radii)"). `progress` hears of each
// Ceres iteration (stage "fit"); returning false stops the solve and throws Cancelled.
FitDesign FitMirrorDesign(const FitDesignSpec& spec, const ProgressCallback& progress = {});

// The design as an axial sensor: mirror radius rim_radius_mm, a pinhole with the rim at
// image_size_px / 2 from the centre (the paper's 2N = image size).
Sensor SensorFromFitDesign(const FitDesign& design, const FitDesignSpec& spec, double rim_radius_mm, int image_size_px);

// How closely an axial sensor follows each characteristic, measured through its own model
// (ComputeAxialRay and the lens projection of the reflection point), so a fitted design
// and any other sensor file (Table 1's, say) are measured the same way.
struct CharacteristicSample {
  double x_mm, omega_deg, h_px;  // reflection radius, object ray angle, image radius
  double viewpoint_z_mm;        // Eq. 6
};
struct CharacteristicReport {
  std::vector<CharacteristicSample> samples;  // x from 0 to the rim
  double rim_h_px = 0.0, rim_omega_deg = 0.0, rim_theta_deg = 0.0;
  // max |h - h_law| (px) for each law through the origin and the rim point.
  double equidistant_max_px = 0.0, constant_aspect_max_px = 0.0, equal_area_max_px = 0.0;
  double viewpoint_spread_mm = 0.0;  // max - min z_v over the mirror
  double LawErrorPx(ImageCharacteristic characteristic) const;
};
// Throws InputError if the sensor is not axial (tilt or decenter), or a ray fails.
CharacteristicReport MeasureCharacteristics(const Sensor& sensor, int samples);
// h_law / h_rim for Omega (rad) and the rim's Omega; NaN for kNone / kSingleViewpoint.
double LawHeightRatio(ImageCharacteristic characteristic, double omega_rad, double rim_omega_rad);

}  // namespace omnical
