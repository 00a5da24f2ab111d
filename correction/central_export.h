// The export-central job: the best-fit central model of a sensor (central_fit.h) for
// objects on a sphere of D mm around V0 (or at infinity), with its error over the field
// at that distance and at others, and the files central tools read: Mei's unified model
// as the YAML cv::omnidir's functions take (K, D, xi), or OCamCalib's calib_results.txt.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "correction/central_fit.h"
#include "model/progress.h"

namespace omnical {

enum class CentralModelKind { kMei, kOCamCalib };
// "mei", "ocamcalib".
std::optional<CentralModelKind> ParseCentralModelKind(const std::string& name);
const char* CentralModelKindName(CentralModelKind kind);

struct CentralExportOptions {
  CentralModelKind model = CentralModelKind::kMei;
  std::optional<double> distance_mm, n;  // at most one: the sphere around V0; neither: infinity
  std::optional<double> v0_mm;           // unset: the V0 minimising the worst error at the distance
  double step_px = 8.0;                  // field sampling grid, omni px (>= 1)
  ProgressCallback progress;             // stage "export-central"

  // "" or "field: problem".
  std::string Check() const;
};

struct CentralErrorAtDistance {
  double n = 0.0;  // mirror rim radii from V0; +inf: at infinity
  double distance_mm = 0.0;
  double rms_px = 0.0, max_px = 0.0;
};

struct CentralExportResult {
  CentralModelKind model = CentralModelKind::kMei;
  ObjectSurface surface;  // fitted for (infinity or a sphere)
  double v0_mm = 0.0;
  double rim_radius_mm = 0.0;
  int image_width_px = 0, image_height_px = 0;
  CentralFitSamples samples;
  MeiModel mei;    // with kMei
  OCamModel ocam;  // with kOCamCalib
  ApproximationError error;  // over `samples`
  // At n = 2, 3, 5, 7, 10, 20, 40, 100 rim radii and infinity, sampled every 2 step_px.
  std::vector<CentralErrorAtDistance> error_at_other_distances;
  // "objects at infinity" or "objects on a sphere of D mm around V0".
  std::string FittedForText() const;
};

// Throws InputError naming the field (e.g. step_px when too few pixels see the mirror),
// Cancelled when the callback says stop.
CentralExportResult ExportCentral(const Sensor& sensor, const CentralExportOptions& options);

// Into DIR (created): the model file (omnidir.yml or calib_results.txt), central.json
// (`sensor_file` as the caller names the sensor) and central_error.csv, atomically.
void WriteCentralExport(const std::string& dir, const CentralExportResult& result, const std::string& sensor_file);

}  // namespace omnical
