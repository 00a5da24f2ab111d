#include "correction/central_export.h"

#include <nlohmann/json.hpp>

#include <opencv2/core.hpp>

#include <cmath>
#include <filesystem>
#include <iomanip>

#include "correction/view_request.h"
#include "model/io/atomic_write.h"
#include "model/input_error.h"
#include "model/object_distance.h"
#include "model/optics.h"

namespace omnical {
namespace {

nlohmann::json MatrixJson(const Eigen::Matrix3d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

// cv::FileStorage with the keys OpenCV's omnidir calibration sample writes, plus the frame.
void WriteMeiYaml(const MeiModel& mei, int width_px, int height_px, const std::string& path, const std::string& fitted_for) {
  WriteFileAtomicallyByPath(path, [&](const std::string& temp_path) {
    cv::FileStorage fs(temp_path, cv::FileStorage::WRITE);
    if (!fs.isOpened()) throw InputError(path + ": cannot write");
    fs << "image_width" << width_px << "image_height" << height_px;
    fs << "camera_matrix" << (cv::Mat_<double>(3, 3) << mei.fx, mei.skew, mei.cx, 0.0, mei.fy, mei.cy, 0.0, 0.0, 1.0);
    fs << "distortion_coefficients" << (cv::Mat_<double>(1, 4) << mei.k1, mei.k2, mei.p1, mei.p2);
    fs << "xi" << (cv::Mat_<double>(1, 1) << mei.xi);
    cv::Mat frame(3, 3, CV_64F);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) frame.at<double>(r, c) = mei.central_from_mirror(r, c);
    fs.writeComment("point_in_model = central_from_mirror * (point_in_mirror - (0, 0, v0_mm)); determinant -1: "
                    "the catadioptric image is mirror-reversed");
    fs << "central_from_mirror" << frame << "v0_mm" << mei.v0_mm << "fitted_for" << fitted_for;
  });
}

// OCamCalib's calib_results.txt, the layout its get_ocam_model() reads.
void WriteOCamResults(const OCamModel& ocam, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << std::setprecision(12);
    out << "#polynomial coefficients for the DIRECT mapping function (ocam_model.ss in MATLAB). These are used by "
           "cam2world\n\n"
        << ocam.pol.size();
    for (double v : ocam.pol) out << ' ' << v;
    out << "\n\n#polynomial coefficients for the inverse mapping function (ocam_model.invpol in MATLAB). These are "
           "used by world2cam\n\n"
        << ocam.invpol.size();
    for (double v : ocam.invpol) out << ' ' << v;
    out << "\n\n#center: \"row\" and \"column\", starting from 0 (C convention)\n\n"
        << ocam.xc_row << ' ' << ocam.yc_col << "\n\n#affine parameters \"c\", \"d\", \"e\"\n\n"
        << ocam.c << ' ' << ocam.d << ' ' << ocam.e << "\n\n#image size: \"height\" and \"width\"\n\n"
        << ocam.height << ' ' << ocam.width << '\n';
  });
}

ObjectSurface SphereAt(double distance_mm) {
  ObjectSurface sphere;
  sphere.kind = ObjectSurface::Kind::kSphere;
  sphere.distance_mm = distance_mm;
  return sphere;
}

}  // namespace

std::optional<CentralModelKind> ParseCentralModelKind(const std::string& name) {
  if (name == "mei") return CentralModelKind::kMei;
  if (name == "ocamcalib") return CentralModelKind::kOCamCalib;
  return std::nullopt;
}

const char* CentralModelKindName(CentralModelKind kind) { return kind == CentralModelKind::kMei ? "mei" : "ocamcalib"; }

std::string CentralExportOptions::Check() const {
  if (distance_mm && n) return "n: give only one of distance_mm and n";
  if (distance_mm || n) {
    const double distance = distance_mm ? *distance_mm : *n;
    if (!std::isfinite(distance) || distance <= 0.0)
      return std::string(n ? "n" : "distance_mm") + ": the object distance must be > 0";
  }
  if (!(step_px >= 1.0)) return "step_px: must be >= 1";
  if (v0_mm)
    if (const std::string why = ViewpointProblem(*v0_mm); !why.empty()) return "v0_mm: " + why;
  return "";
}

std::string CentralExportResult::FittedForText() const {
  return surface.kind == ObjectSurface::Kind::kInfinity
             ? "objects at infinity"
             : "objects on a sphere of " + std::to_string(surface.distance_mm) + " mm around V0";
}

CentralExportResult ExportCentral(const Sensor& sensor, const CentralExportOptions& options) {
  if (const std::string why = options.Check(); !why.empty()) throw InputError(why);
  CentralExportResult result;
  result.model = options.model;
  const double rim = result.rim_radius_mm = sensor.rim_radius_mm();
  result.image_width_px = sensor.image_width_px(), result.image_height_px = sensor.image_height_px();
  if (options.distance_mm || options.n) {
    result.surface = SphereAt(options.distance_mm ? *options.distance_mm : *options.n * rim);
    if (const std::string why = ObjectDistanceProblem(result.surface.distance_mm); !why.empty())
      throw InputError(std::string(options.n ? "n" : "distance_mm") + ": " + why);
  }
  const double reference_mm = ReferenceDistanceMm(sensor, result.surface);
  const double v0_mm = result.v0_mm = ResolveV0Mm(AnalyzeField(sensor, 360, reference_mm), reference_mm, options.v0_mm);

  // Other distances: how wrong the export is for objects nearer or farther than assumed.
  const std::vector<double> ns = {2, 3, 5, 7, 10, 20, 40, 100};
  ProgressReporter progress(options.progress, "export-central", static_cast<long>(ns.size()) + 3);
  result.samples = SampleField(sensor, result.surface, v0_mm, options.step_px);
  progress.Step();
  if (result.samples.pixels.size() < 50)
    throw InputError("step_px: only " + std::to_string(result.samples.pixels.size()) + " pixels see the mirror at a grid of " +
                     std::to_string(options.step_px) + " px: nothing to fit");
  const bool mei = options.model == CentralModelKind::kMei;
  if (mei) result.mei = FitMei(result.samples, v0_mm);
  else result.ocam = FitOCam(sensor, result.samples, v0_mm);
  auto error_of = [&](const CentralFitSamples& s) { return mei ? ErrorOf(result.mei, s) : ErrorOf(result.ocam, s); };
  result.error = error_of(result.samples);
  progress.Step();
  for (double n : ns) {
    const ApproximationError e = error_of(SampleField(sensor, SphereAt(n * rim), v0_mm, 2.0 * options.step_px));
    result.error_at_other_distances.push_back({n, n * rim, e.rms_px, e.max_px});
    progress.Step();
  }
  const ApproximationError at_infinity = error_of(SampleField(sensor, ObjectSurface{}, v0_mm, 2.0 * options.step_px));
  result.error_at_other_distances.push_back({HUGE_VAL, HUGE_VAL, at_infinity.rms_px, at_infinity.max_px});
  progress.Step();
  return result;
}

void WriteCentralExport(const std::string& dir, const CentralExportResult& result, const std::string& sensor_file) {
  CreateOutputDirectory(dir);
  const std::filesystem::path out(dir);
  const ObjectSurface& surface = result.surface;
  nlohmann::json elsewhere = nlohmann::json::array();
  for (const CentralErrorAtDistance& e : result.error_at_other_distances) {
    if (std::isfinite(e.n))
      elsewhere.push_back({{"n", e.n}, {"distance_mm", e.distance_mm}, {"rms_px", e.rms_px}, {"max_px", e.max_px}});
    else
      elsewhere.push_back({{"n", "infinity"}, {"rms_px", e.rms_px}, {"max_px", e.max_px}});
  }
  nlohmann::json j;
  j["model"] = CentralModelKindName(result.model);
  j["sensor"] = sensor_file;
  j["fitted_for"] = surface.kind == ObjectSurface::Kind::kInfinity
                        ? nlohmann::json("infinity")
                        : nlohmann::json({{"surface", "sphere"},
                                          {"distance_mm", surface.distance_mm},
                                          {"n", surface.distance_mm / result.rim_radius_mm}});
  j["v0_mm"] = result.v0_mm;
  j["samples"] = result.samples.pixels.size();
  j["approximation_error_px"] = {{"rms", result.error.rms_px}, {"max", result.error.max_px}};
  j["error_at_other_distances"] = elsewhere;
  if (result.model == CentralModelKind::kMei) {
    const MeiModel& mei = result.mei;
    j["file"] = "omnidir.yml";
    j["parameters"] = {{"fx", mei.fx}, {"fy", mei.fy}, {"cx", mei.cx}, {"cy", mei.cy}, {"skew", mei.skew}, {"xi", mei.xi},
                       {"k1", mei.k1}, {"k2", mei.k2}, {"p1", mei.p1}, {"p2", mei.p2}};
    j["central_from_mirror"] = MatrixJson(mei.central_from_mirror);
    WriteMeiYaml(mei, result.image_width_px, result.image_height_px, (out / "omnidir.yml").string(), result.FittedForText());
  } else {
    const OCamModel& ocam = result.ocam;
    j["file"] = "calib_results.txt";
    j["parameters"] = {{"pol", ocam.pol}, {"invpol", ocam.invpol}, {"xc_row", ocam.xc_row}, {"yc_col", ocam.yc_col},
                       {"c", ocam.c}, {"d", ocam.d}, {"e", ocam.e}};
    j["central_from_mirror"] = MatrixJson(ocam.central_from_mirror);
    WriteOCamResults(ocam, (out / "calib_results.txt").string());
  }
  j["frame"] = "point_in_model = central_from_mirror * (point_in_mirror - (0, 0, v0_mm)); mirror frame as in sensor.yaml";
  WriteFileAtomically((out / "central.json").string(), [&](std::ostream& stream) { stream << j.dump(2) << '\n'; });
  const ApproximationError& error = result.error;
  WriteFileAtomically((out / "central_error.csv").string(), [&](std::ostream& stream) {
    stream << "u_px,v_px,omega_deg,error_px\n" << std::setprecision(10);
    for (size_t i = 0; i < result.samples.pixels.size(); ++i)
      stream << result.samples.pixels[i].x() << ',' << result.samples.pixels[i].y() << ',' << error.omega_deg[i] << ','
             << error.error_px[i] << '\n';
  });
}

}  // namespace omnical
