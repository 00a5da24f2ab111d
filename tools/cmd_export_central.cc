// omnical export-central: the best-fit central model of a (non-central) sensor for tools
// that only take central cameras: Mei's unified model as a YAML cv::omnidir functions
// read (K, D, xi), or OCamCalib's calib_results.txt; with the approximation error over the
// field, in omni px, at the chosen object distance and at others (central_error.json/png).
#include <nlohmann/json.hpp>

#include <opencv2/core.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <optional>
#include <ostream>

#include "correction/central_fit.h"
#include "model/atomic_write.h"
#include "model/input_error.h"
#include "model/optics.h"
#include "tools/commands.h"
#include "calib/report/plot.h"
#include "tools/progress.h"
#include "tools/view_setup.h"

namespace omnical::cli {
namespace {

struct Options {
  std::string sensor_path, model, out_dir;
  std::optional<double> distance_mm, n, v0_mm;
  double step_px = 8.0;
};

nlohmann::json MatrixJson(const Eigen::Matrix3d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

// cv::FileStorage with the keys OpenCV's omnidir calibration sample writes, plus the frame.
void WriteMeiYaml(const MeiModel& mei, const Sensor& sensor, const std::string& path, const std::string& distance_text) {
  WriteFileAtomicallyByPath(path, [&](const std::string& temp_path) {
    cv::FileStorage fs(temp_path, cv::FileStorage::WRITE);
    if (!fs.isOpened()) throw InputError(path + ": cannot write");
    fs << "image_width" << sensor.image_width_px() << "image_height" << sensor.image_height_px();
    fs << "camera_matrix" << (cv::Mat_<double>(3, 3) << mei.fx, mei.skew, mei.cx, 0.0, mei.fy, mei.cy, 0.0, 0.0, 1.0);
    fs << "distortion_coefficients" << (cv::Mat_<double>(1, 4) << mei.k1, mei.k2, mei.p1, mei.p2);
    fs << "xi" << (cv::Mat_<double>(1, 1) << mei.xi);
    cv::Mat frame(3, 3, CV_64F);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) frame.at<double>(r, c) = mei.central_from_mirror(r, c);
    fs.writeComment("point_in_model = central_from_mirror * (point_in_mirror - (0, 0, v0_mm)); determinant -1: "
                    "the catadioptric image is mirror-reversed");
    fs << "central_from_mirror" << frame << "v0_mm" << mei.v0_mm << "fitted_for" << distance_text;
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

void Run(const Options& options, const Context& context) {
  const Sensor sensor = LoadSensorYaml(options.sensor_path);
  const double rim = sensor.rim_radius_mm();
  ObjectSurface surface;
  if (options.distance_mm || options.n) {
    surface.kind = ObjectSurface::Kind::kSphere;
    surface.distance_mm = options.distance_mm ? *options.distance_mm : *options.n * rim;
    if (!std::isfinite(surface.distance_mm) || surface.distance_mm <= 0.0)
      throw InputError(std::string(options.n ? "--n" : "--distance-mm") + ": the object distance must be > 0");
  }
  if (!(options.step_px >= 1.0)) throw InputError("--step-px: must be >= 1");
  const bool at_infinity = surface.kind == ObjectSurface::Kind::kInfinity;
  const double reference_mm = ReferenceDistanceMm(sensor, surface);
  const double v0_mm = ResolveV0Mm(AnalyzeField(sensor, 360, reference_mm), reference_mm, options.v0_mm);
  const std::string distance_text =
      at_infinity ? "objects at infinity" : "objects on a sphere of " + std::to_string(surface.distance_mm) + " mm around V0";

  // Other distances: how wrong the export is for objects nearer or farther than assumed.
  std::vector<double> ns = {2, 3, 5, 7, 10, 20, 40, 100};
  Progress progress("export-central", static_cast<long>(ns.size()) + 3, context.quiet);
  const CentralFitSamples samples = SampleField(sensor, surface, v0_mm, options.step_px);
  progress.Advance();
  if (samples.pixels.size() < 50)
    throw InputError(options.sensor_path + ": only " + std::to_string(samples.pixels.size()) +
                     " pixels see the mirror at --step-px " + std::to_string(options.step_px) + ": nothing to fit");
  MeiModel mei;
  OCamModel ocam;
  if (options.model == "mei") {
    mei = FitMei(samples, v0_mm);
  } else {
    ocam = FitOCam(sensor, samples, v0_mm);
  }
  auto error_of = [&](const CentralFitSamples& s) { return options.model == "mei" ? ErrorOf(mei, s) : ErrorOf(ocam, s); };
  const ApproximationError error = error_of(samples);
  progress.Advance();
  auto error_at = [&](const ObjectSurface& other) { return error_of(SampleField(sensor, other, v0_mm, 2.0 * options.step_px)); };
  nlohmann::json elsewhere = nlohmann::json::array();
  for (double n : ns) {
    ObjectSurface other;
    other.kind = ObjectSurface::Kind::kSphere;
    other.distance_mm = n * rim;
    const ApproximationError e = error_at(other);
    elsewhere.push_back({{"n", n}, {"distance_mm", n * rim}, {"rms_px", e.rms_px}, {"max_px", e.max_px}});
    progress.Advance();
  }
  const ApproximationError at_infinity_error = error_at(ObjectSurface{});
  elsewhere.push_back({{"n", "infinity"}, {"rms_px", at_infinity_error.rms_px}, {"max_px", at_infinity_error.max_px}});
  progress.Advance();

  const std::filesystem::path dir(options.out_dir);
  CreateOutputDirectory(dir);
  nlohmann::json result;
  result["model"] = options.model;
  result["sensor"] = options.sensor_path;
  result["fitted_for"] = at_infinity ? nlohmann::json("infinity") : nlohmann::json({{"surface", "sphere"}, {"distance_mm", surface.distance_mm}, {"n", surface.distance_mm / rim}});
  result["v0_mm"] = v0_mm;
  result["samples"] = samples.pixels.size();
  result["approximation_error_px"] = {{"rms", error.rms_px}, {"max", error.max_px}};
  result["error_at_other_distances"] = elsewhere;
  if (options.model == "mei") {
    result["file"] = "omnidir.yml";
    result["parameters"] = {{"fx", mei.fx}, {"fy", mei.fy}, {"cx", mei.cx}, {"cy", mei.cy}, {"skew", mei.skew}, {"xi", mei.xi},
                            {"k1", mei.k1}, {"k2", mei.k2}, {"p1", mei.p1}, {"p2", mei.p2}};
    result["central_from_mirror"] = MatrixJson(mei.central_from_mirror);
    WriteMeiYaml(mei, sensor, (dir / "omnidir.yml").string(), distance_text);
  } else {
    result["file"] = "calib_results.txt";
    result["parameters"] = {{"pol", ocam.pol}, {"invpol", ocam.invpol}, {"xc_row", ocam.xc_row}, {"yc_col", ocam.yc_col},
                            {"c", ocam.c}, {"d", ocam.d}, {"e", ocam.e}};
    result["central_from_mirror"] = MatrixJson(ocam.central_from_mirror);
    WriteOCamResults(ocam, (dir / "calib_results.txt").string());
  }
  result["frame"] = "point_in_model = central_from_mirror * (point_in_mirror - (0, 0, v0_mm)); mirror frame as in sensor.yaml";
  WriteOutput((dir / "central.json").string(), [&](std::ostream& out) { out << result.dump(2) << '\n'; });

  WriteOutput((dir / "central_error.csv").string(), [&](std::ostream& out) {
    out << "u_px,v_px,omega_deg,error_px\n" << std::setprecision(10);
    for (size_t i = 0; i < samples.pixels.size(); ++i)
      out << samples.pixels[i].x() << ',' << samples.pixels[i].y() << ',' << error.omega_deg[i] << ',' << error.error_px[i] << '\n';
  });
  // The error over the field, per sample, against Omega.
  char title[200];
  std::snprintf(title, sizeof title, "%s central model fitted for %s: error of each field sample",
                options.model == "mei" ? "Mei (cv::omnidir)" : "OCamCalib", distance_text.c_str());
  PlotPanel panel{title, "Omega (deg)", "error (px in the omni image)"};
  panel.series.push_back({"samples", error.omega_deg, error.error_px, SeriesColor(0)});
  panel.series.back().markers_only = true;
  WritePng((dir / "central_error.png").string(), RenderPanel(panel, 900, 560));
  if (!context.quiet)
    std::printf("%s central model for %s, V0 = %.3f mm: %.4f px RMS, %.4f px max over %zu field samples -> %s\n",
                options.model.c_str(), distance_text.c_str(), v0_mm, error.rms_px, error.max_px, samples.pixels.size(),
                options.out_dir.c_str());
}

}  // namespace

Command ExportCentralCommand() {
  return {"export-central", "Best-fit central model (Mei for cv::omnidir, or OCamCalib) with its error over the field",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto options = std::make_shared<Options>();
            sub.add_option("--sensor", options->sensor_path, "Sensor file (YAML)")->required();
            sub.add_option("--model", options->model, "mei (cv::omnidir YAML) or ocamcalib (calib_results.txt)")
                ->required()
                ->check(CLI::IsMember({"mei", "ocamcalib"}));
            auto* d = sub.add_option("--distance-mm", options->distance_mm, "Objects on a sphere of D mm around V0 (default: infinity)");
            auto* n = sub.add_option("--n", options->n, "Objects at n mirror rim radii from V0");
            d->excludes(n);
            sub.add_option("--v0", options->v0_mm, "Viewpoint V0, z on the mirror axis (mm, mirror frame); "
                                                   "default: the one minimising the worst error at the distance");
            sub.add_option("--step-px", options->step_px, "Field sampling grid, omni px")->capture_default_str();
            sub.add_option("--out", options->out_dir, "Output directory")->required();
            return [options, &context]() { Run(*options, context); };
          }};
}

}  // namespace omnical::cli
