// The `design fit` job: Ohte & Tsuzuki's design by parameters (Table 1) solved with Ceres
// (model/design/mirror_design_fit.h), as an axial sensor in mm, with the image laws the
// design achieves measured through that sensor's own model, and optionally those of
// another sensor for comparison. No printing, no files: model/design/design_files.h writes
// the result, calib/report draws it.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "model/design/mirror_design_fit.h"
#include "model/io/profile_table.h"
#include "model/progress.h"
#include "model/sensor.h"

namespace omnical {

struct DesignFitOptions {
  // profile, terms, rim_omega_deg, rim_theta_deg, characteristic (kNone for a
  // family with no freedom left; DefaultCharacteristic gives the usual one).
  FitDesignSpec spec;
  double rim_radius_mm = 43.9;  // mirror radius M at the rim: scales the normalised design
  int image_size_px = 1000;     // square; the rim images at half its width (the paper's 2N)
  // Another axial sensor measured the same way (e.g. Table 1's), and the name messages
  // and reports give it (its file).
  std::optional<Sensor> compare;
  std::string compare_source;
  int characteristic_samples = 1000;  // mirror radii the laws are measured at
  int profile_samples = 2000;         // intervals of the profile table, vertex to rim
  ProgressCallback progress;          // stages "measure compared", "fit", "measure"
  // "field: problem" (the spec's fields, rim_radius_mm, image_size_px, ...), else empty.
  std::string Check() const;
};

// The characteristic a family is usually shaped for: single viewpoint for a hyperboloid,
// equidistant for any other with freedom left after the rim targets (a polynomial of two
// or more terms), none for a family the rim targets fix (a sphere, a one-term polynomial).
ImageCharacteristic DefaultCharacteristic(const std::string& profile, int terms);

struct DesignFitResult {
  FitDesignSpec spec;
  FitDesign design;
  double rim_radius_mm = 0.0;
  Sensor sensor;
  ProfileTable profile;  // in mm, vertex to rim, through the sensor's own model
  CharacteristicReport achieved;
  std::optional<CharacteristicReport> compared;
  std::string compared_source;
  // The law the curves are measured against: the characteristic, or equidistant where it is
  // none or single viewpoint (which has no image law).
  ImageCharacteristic law = ImageCharacteristic::kEquidistant;
};

// Table 1's names for the normalised parameters in its order: sphere {A, m}; hyperboloid
// {A, B, m}; polynomial {c1, ..., cn, m}.
std::vector<std::pair<std::string, double>> NormalisedParameters(const FitDesign& design);

// Throws InputError "design fit: field: problem" for options Check() refuses or a design
// out of the family's reach; "<compare_source>: problem" when the compared sensor cannot
// be measured (before any fitting); Cancelled when progress says stop.
DesignFitResult DesignMirrorFit(const DesignFitOptions& options);

}  // namespace omnical
