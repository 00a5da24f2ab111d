// The `design ode` job: a mirror from Gächter's reflection ODE for an imaging law
// (model/design/mirror_design_ode.h), as a tabulated sensor every other job takes, with the
// law checked through omnical's own ray tracing of that sensor on cylinders around the
// reference distance (the seed's Figs. 9, 10 and 14). No printing, no files: the result's
// files are written by model/design/design_files.h, its figures by calib/report.
#pragma once

#include <string>
#include <vector>

#include "model/design/designed_sensor.h"
#include "model/design/mirror_design_ode.h"
#include "model/io/profile_table.h"
#include "model/progress.h"
#include "model/sensor.h"

namespace omnical {

struct DesignOdeOptions {
  OdeDesignSpec spec;
  int samples = 20001;       // profile samples, uniform in the mirror radius
  int image_size_px = 1000;  // the designed sensor's square image
  // The profile table the sensor names (its mirror.table), relative to the sensor file.
  std::string table_file = "profile.csv";
  ProgressCallback progress;  // stages "ode", "trace law"
  // "field: problem" (samples, image_size_px, or the spec's own fields), else empty.
  std::string Check() const;
};

struct DesignOdeResult {
  OdeDesignSpec spec;
  OdeDesign design;
  ProfileTable profile;           // from the vertex: radius t, sag F(t) - F(0), slope dF/dt
  Sensor sensor;                  // tabulated mirror from `profile`, pinhole lens
  double vertex_height_mm = 0.0;  // F0 = F(0): image plane to mirror vertex
  double m_mm = 0.0;              // lens to vertex, F0 - f
  double pixel_pitch_mm = 0.0;
  // The law ratio traced at kLawCheckDistanceFactors x d; law_ratio[kReferenceCurve] is at d.
  std::vector<LawRatioCurve> law_ratio;
  // max |ratio - 1| at d; HUGE_VAL where a ray missed.
  double max_law_error_rel = 0.0;

  static constexpr double kLawCheckDistanceFactors[] = {0.5, 0.75, 1.0, 1.5, 2.0};
  static constexpr int kReferenceCurve = 2;
  // Intervals of rho for the law ratio: 1 % of the imager each.
  static constexpr int kLawRatioIntervals = 100;
  const LawRatioCurve& reference_curve() const { return law_ratio[kReferenceCurve]; }
};

// Throws InputError "design ode: field: problem" for options Check() refuses, and the
// solver's InputError when the law cannot make a mirror; Cancelled when progress says stop.
DesignOdeResult DesignMirrorOde(const DesignOdeOptions& options);

}  // namespace omnical
