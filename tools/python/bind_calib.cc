// Calibration from Python: omnical.Target (calib/target.h), omnical.detect
// (calib/image_detection.h) -> Detections (calib/detections.h), omnical.calibrate
// (calib/calibrate.h) -> CalibrationResult, whose save() writes what `omnical calibrate`
// writes, and load_calibration (calib/calibration_json.h). The inputs the CLI takes as
// flags are keyword arguments named as the library's option fields, so its
// "field: problem" messages name them; images may also be NumPy arrays.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "calib/calibrate.h"
#include "calib/calibration_json.h"
#include "calib/calibration_summary.h"
#include "calib/fit_covariance.h"
#include "calib/image_file.h"
#include "calib/projection_diff.h"
#include "calib/report/calibration_report.h"
#include "model/input_error.h"
#include "model/io/atomic_write.h"
#include "model/io/sensor_yaml.h"
#include "tools/python/bindings.h"
#include "tools/python/py_common.h"
#include "tools/python/py_image.h"

namespace omnical::python {
namespace {

using namespace pybind11::literals;

// A target and the spec file it was read from ("" when built in code): detections and
// the calibration record name it, as the CLI's --target.
struct PyTarget {
  CalibrationTarget board;
  std::string spec_path;
};

// What detect() found: the corners, each image's rim circle if asked, the warnings.
struct PyDetections {
  DetectionSet set;
  std::vector<RimCircle> rim_circles;
  std::vector<CalibrationWarning> warnings;
};

struct PyCalibration {
  CalibrationResult result;
  bool detected = false;              // corners found here: save() writes detections.json
  CalibrationOptions report_options;  // what the report figures read (progress cleared)
  std::vector<NamedImage> images;     // given in memory: the report draws on them
};

int ThreadsOf(int threads) { return threads == 0 ? static_cast<int>(std::max(1u, std::thread::hardware_concurrency())) : threads; }

bool IsPath(const py::handle& object) { return py::isinstance<py::str>(object) || py::hasattr(object, "__fspath__"); }

std::string TypeName(const py::handle& object) { return py::str(py::type::of(object).attr("__name__")); }

PyTarget TargetOf(const py::handle& target) {
  if (py::isinstance<PyTarget>(target)) return target.cast<PyTarget>();
  if (!IsPath(target)) throw InputError("target: expected an omnical.Target or the path of a target spec, got " + TypeName(target));
  const std::string path = PathOf(target);
  return {CalibrationTarget::FromYaml(path), path};
}

std::optional<Sensor> GuessOf(const py::handle& guess, std::string* name, DesignTolerances* tolerances) {
  if (guess.is_none()) return std::nullopt;
  if (py::isinstance<Sensor>(guess)) {
    *name = "guess";
    return guess.cast<Sensor>();
  }
  if (!IsPath(guess)) throw InputError("guess: expected an omnical.Sensor or the path of a sensor file, got " + TypeName(guess));
  *name = PathOf(guess);
  Sensor sensor = LoadSensorYaml(*name);
  // A sensor file's design tolerances come with it, as with the CLI's --sensor.
  if (tolerances) *tolerances = ReadDesignTolerances(*name, sensor);
  return sensor;
}

// A uint8 image as one grey channel (BGR and BGRA as cv2 reads them).
cv::Mat GreyOf(const py::handle& array, const std::string& name) {
  const cv::Mat image = MatOf(array, name.c_str());
  // A copy: the array may go away while the job runs (a lazy sequence's temporary, a
  // list emptied from the progress callback).
  if (image.channels() == 1) return image.clone();
  cv::Mat grey;
  cv::cvtColor(image, grey, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return grey;
}

// detect()'s and calibrate()'s `images`: a directory or glob pattern (as the CLI's
// --images), a list of paths, a list of arrays (named by index) or a dict name -> array.
// Arrays in memory are copied (as grey), so nothing the caller does later can free them.
struct ImageInput {
  std::vector<std::string> paths;
  std::vector<NamedImage> images;
  std::string source;  // named in messages
};

ImageInput ImagesOf(const py::handle& images) {
  ImageInput input;
  if (IsPath(images)) {
    input.source = PathOf(images);
    input.paths = ListImages(input.source);
  } else if (py::isinstance<py::dict>(images)) {
    for (const auto& [name, array] : py::reinterpret_borrow<py::dict>(images)) {
      const std::string label = py::str(name);
      input.images.push_back({label, GreyOf(array, "images['" + label + "']")});
    }
  } else if (py::isinstance<py::sequence>(images) && !py::isinstance<py::array>(images)) {
    size_t index = 0;
    for (const py::handle item : images) {
      if (IsPath(item)) {
        input.paths.push_back(PathOf(item));
      } else {
        input.images.push_back({std::to_string(index), GreyOf(item, "images[" + std::to_string(index) + "]")});
      }
      ++index;
    }
    if (!input.paths.empty() && !input.images.empty()) throw InputError("images: a list of paths or of arrays, not both");
  } else {
    throw InputError("images: expected a directory or glob pattern, a list of paths or of uint8 arrays, or a dict "
                     "name -> array, got " + TypeName(images));
  }
  const size_t count = input.paths.size() + input.images.size();
  if (count == 0) throw InputError("images: no images given");
  // Named in messages ("list of 2 images: images: ... too few"), as the CLI names the directory.
  if (!IsPath(images))
    input.source = (py::isinstance<py::dict>(images) ? "dict of " : "list of ") + std::to_string(count) + " images";
  return input;
}

py::array_t<double> PointsArray(const std::vector<Eigen::Vector2d>& points) {
  Eigen::Matrix2Xd columns(2, points.size());
  for (size_t i = 0; i < points.size(); ++i) columns.col(i) = points[i];
  return RowsArrayOf<2>(std::move(columns));
}

py::dict PoseMatrices(const std::map<std::string, TargetPose>& poses) {
  py::dict out;
  for (const auto& [image, pose] : poses) {
    Eigen::Matrix4d camera_from_target = Eigen::Matrix4d::Identity();
    camera_from_target.topLeftCorner<3, 3>() = pose.camera_from_target_rotation.toRotationMatrix();
    camera_from_target.topRightCorner<3, 1>() = pose.camera_from_target_translation_mm;
    out[py::str(image)] = py::cast(camera_from_target);
  }
  return out;
}

// A distance for Python: inf where the library's stands for infinity (kInfinityMm).
double PythonDistanceMm(double distance_mm) { return distance_mm >= kInfinityMm ? HUGE_VAL : distance_mm; }

// A projection difference's summary (as calibration.json's cross_validation and diff.json).
py::dict DiffDict(const ProjectionDiff& d) {
  return py::dict("distance_mm"_a = PythonDistanceMm(d.distance_mm), "rms_px"_a = d.rms_px,
                  "median_px"_a = d.median_px, "max_px"_a = d.max_px, "unaligned_rms_px"_a = d.unaligned_rms_px,
                  "compared"_a = d.compared, "moved_off_mirror"_a = d.moved_off_mirror, "aligned"_a = d.aligned,
                  "aligned_at_mm"_a = PythonDistanceMm(d.aligned_at_mm),
                  "rotation_deg"_a = d.rotation_deg,
                  "translation_mm"_a = py::make_tuple(d.translation_mm.x(), d.translation_mm.y(), d.translation_mm.z()));
}

// The record's fields, shared by CalibrationRecord and CalibrationResult (which reads
// them from its record), so a result and a calibration.json read back look alike.
template <typename Holder, typename Get>
void AddRecordFields(py::class_<Holder>& cls, Get record) {
  const auto field = [&](const char* name, auto member, const char* doc) {
    cls.def_property_readonly(name, [record, member](const Holder& holder) { return record(holder).*member; }, doc);
  };
  field("rms_px", &CalibrationRecord::rms_px, "Reprojection RMS per corner over the inliers (px).");
  field("rms_all_px", &CalibrationRecord::rms_all_px,
        "Reprojection RMS per corner over every fitted corner, outliers included (px).");
  field("converged", &CalibrationRecord::converged, "Whether the solver converged.");
  field("observations", &CalibrationRecord::observations, "Corners in the fit.");
  field("outliers", &CalibrationRecord::outliers, "Corners removed as gross outliers.");
  field("dropped", &CalibrationRecord::dropped, "Corners not projectable at the start.");
  field("unrefined_corners_left_out", &CalibrationRecord::unrefined_corners_left_out,
        "Corners whose sub-pixel refinement failed, left out of the fit.");
  field("solver_report", &CalibrationRecord::solver_report, "Ceres' one-line report.");
  field("fixed_blocks", &CalibrationRecord::fixed_blocks, "The parameter blocks held constant (set of str).");
  field("robust_loss_px", &CalibrationRecord::robust_loss_px, "The robust loss scale used (px; 0: least squares).");
  field("covariance_ok", &CalibrationRecord::covariance_ok, "Whether the covariance could be computed.");
  field("start", &CalibrationRecord::start, "Where the fit started: the guess (its file) or the rim circle.");
  field("detection_passes", &CalibrationRecord::detection_passes, "Detection passes made (2: re-detected through the first fit; 3: through the second, or after boards pass 2 found).");
  field("nearest_target_mm", &CalibrationRecord::nearest_target_mm, "Distance of the nearest fitted board from the lens (mm).");
  field("farthest_target_mm", &CalibrationRecord::farthest_target_mm, "Distance of the farthest fitted board (mm).");
  field("views_left_out", &CalibrationRecord::views_left_out, "dict image -> why it was left out of the fit.");
  field("views_skipped", &CalibrationRecord::views_skipped,
        "dict image -> why no view was made of it (unreadable, another size, no board found, no starting pose).");
  field("outlier_threshold_px", &CalibrationRecord::outlier_threshold_px, "|residual| beyond which corners were removed (px).");
  field("per_view_outliers", &CalibrationRecord::per_view_outliers, "dict image -> corners removed as outliers.");
  field("sigma_px", &CalibrationRecord::sigma_px, "Corner noise per coordinate the covariance is scaled by (px).");
  field("tolerances", &CalibrationRecord::tolerances, "The design tolerances applied (dict name -> one std).");
  field("guess_rim_radius_mm", &CalibrationRecord::guess_rim_radius_mm, "The start's mirror rim radius (mm).");
  field("fitted_rim_radius_mm", &CalibrationRecord::fitted_rim_radius_mm, "The fitted sensor's rim radius (mm).");
  field("covariance_names", &CalibrationRecord::covariance_names, "The covariance's rows: parameter names (empty without one).");
  field("covariance", &CalibrationRecord::covariance,
        "Covariance of the free sensor parameters (poses marginalised), float64 (K, K), in covariance_names' order and "
        "the parameters' units.");
  field("per_view_rms_px", &CalibrationRecord::per_view_rms_px, "dict image -> RMS of its corners (px; NaN: left out).");
  field("per_view_weight", &CalibrationRecord::per_view_weight,
        "dict image -> the weight its corners had in the fit (view_weights=True: pooled noise / the view's); empty otherwise.");
  cls.def_property_readonly(
      "correlation", [record](const Holder& holder) { return Eigen::MatrixXd(CorrelationOf(record(holder).covariance)); },
      "The covariance as correlations, float64 (K, K), unit diagonal, in covariance_names' order.");
  field("scale_block_condition", &CalibrationRecord::scale_block_condition,
        "Condition number of the scale-like parameters' correlation block (focal, m, mirror size); NaN without a "
        "covariance.");
  cls.def_property_readonly(
      "parameters",
      [record](const Holder& holder) {
        py::dict out;  // insertion order: the fit's order (read back from JSON: by name)
        for (const ParameterEstimate& p : record(holder).parameters) out[py::str(p.name)] = py::cast(p);
        return out;
      },
      "dict name -> Parameter (value, std, fixed), names with their unit (fx_px, m_mm, tilt_x_deg, ...).");
  cls.def_property_readonly(
      "poses", [record](const Holder& holder) { return PoseMatrices(record(holder).poses); },
      "dict image -> camera_from_target, float64 (4, 4), translation in mm (fitted views only).");
  cls.def_property_readonly(
      "rim_circle",
      [record](const Holder& holder) -> py::object {
        const auto& rim = record(holder).rim_circle;
        if (!rim) return py::none();
        return py::cast(RimCircle{rim->centre_px, rim->radius_px, rim->inlier_fraction, rim->rms_px});
      },
      "The mirror's rim circle the fit started from (RimCircle), or None (started from a guess).");
  cls.def_property_readonly(
      "leave_one_out",
      [record](const Holder& holder) {
        py::dict out;
        for (const auto& [name, s] : record(holder).leave_one_out)
          out[py::str(name)] = py::dict("min"_a = s.min, "max"_a = s.max, "std"_a = s.std);
        return out;
      },
      "dict parameter -> {'min', 'max', 'std'} over the fits without each view (empty unless leave_one_out=True).");
  cls.def_property_readonly(
      "board_warp",
      [record](const Holder& holder) -> py::object {
        const auto& w = record(holder).board_warp;
        if (!w) return py::none();
        py::dict relief;
        for (const auto& [id, offset_mm] : w->warp.relief_mm) {
          const auto std_mm = w->relief_std_mm.find(id);
          relief[py::int_(id)] = py::make_tuple(offset_mm, std_mm == w->relief_std_mm.end() ? NAN : std_mm->second);
        }
        return py::dict("x_mm"_a = w->warp.x_mm, "y_mm"_a = w->warp.y_mm, "std_x_mm"_a = w->std_x_mm,
                        "std_y_mm"_a = w->std_y_mm, "relief"_a = relief);
      },
      "The board's fitted warp (board_warp=True, the default): dict x_mm, y_mm (deflection at the centre along each "
      "board axis) and their std_x_mm, std_y_mm, and relief: corner id -> (offset_mm, std_mm), each corner's own "
      "out-of-plane offset on top of the warp (empty unless the relief was fitted: board_relief); None unless fitted.");
  cls.def_property_readonly(
      "knot_choice",
      [record](const Holder& holder) -> py::object {
        const auto& k = record(holder).knot_choice;
        if (!k) return py::none();
        return py::dict("base_profile"_a = k->base_profile, "candidates"_a = k->candidates, "held_out_rms_px"_a = k->held_out_rms_px,
                        "held_out_corners"_a = k->held_out_corners, "folds"_a = k->folds, "chosen"_a = k->chosen);
      },
      "The spline's knot count chosen by held-out folds (knots='auto', or by default without a guess through the "
      "orthographic lens): dict base_profile, candidates (0: base_profile, no spline), held_out_rms_px (per "
      "candidate), held_out_corners, folds, chosen; None unless chosen.");
  const auto named_choice = [](const std::optional<NamedChoice>& choice) -> py::object {
    if (!choice) return py::none();
    return py::dict("candidates"_a = choice->candidates, "held_out_rms_px"_a = choice->held_out_rms_px,
                    "held_out_corners"_a = choice->held_out_corners, "folds"_a = choice->folds, "chosen"_a = choice->chosen);
  };
  cls.def_property_readonly(
      "lens_choice", [record, named_choice](const Holder& holder) { return named_choice(record(holder).lens_choice); },
      "Without a guess, the lens chosen by held-out folds (lens='auto', the default): dict candidates, held_out_rms_px (per "
      "candidate, NaN where it failed), held_out_corners, folds, chosen; None unless chosen.");
  cls.def_property_readonly(
      "profile_choice", [record, named_choice](const Holder& holder) { return named_choice(record(holder).profile_choice); },
      "Without a guess, the mirror family chosen by held-out folds (profile='auto', the default): dict candidates "
      "(polynomial, even_asphere), held_out_rms_px, held_out_corners, folds, chosen; None unless chosen.");
  cls.def_property_readonly(
      "tangential_choice",
      [record, named_choice](const Holder& holder) { return named_choice(record(holder).tangential_choice); },
      "Whether a pinhole's p1, p2 are fitted, chosen by held-out folds (tangential='auto', or unset without a guess): dict candidates (held, "
      "fitted), held_out_rms_px, held_out_corners, folds, chosen; None unless chosen.");
  cls.def_property_readonly(
      "relief_choice",
      [record, named_choice](const Holder& holder) { return named_choice(record(holder).relief_choice); },
      "Whether the board's relief is fitted, chosen by held-out folds (board_relief='auto', or unset without a guess): "
      "dict candidates (warp, warp+relief), held_out_rms_px, held_out_corners, folds, chosen; None unless chosen.");
  cls.def_property_readonly(
      "holdout",
      [record](const Holder& holder) -> py::object {
        const CalibrationRecord& r = record(holder);
        if (!r.holdout) return py::none();
        const HeldOutViews& h = *r.holdout;
        return py::dict("views"_a = h.images, "rms_px"_a = h.rms_px, "inlier_rms_px"_a = h.inlier_rms_px,
                        "corners"_a = h.corners, "outliers"_a = h.outliers, "per_view_rms_px"_a = h.per_view_rms_px,
                        "not_evaluated"_a = h.not_evaluated, "training_rms_px"_a = r.rms_all_px);
      },
      "The held-out views (holdout=K): dict views, rms_px (all their corners, sensor held, poses fitted), "
      "inlier_rms_px, corners, outliers, per_view_rms_px, not_evaluated, training_rms_px; None unless asked.");
  cls.def_property_readonly(
      "holdout_folds",
      [record](const Holder& holder) -> py::object {
        const auto& h = record(holder).holdout_folds;
        if (!h) return py::none();
        py::list folds;
        for (const HeldOutFolds::Fold& fold : h->folds)
          folds.append(py::dict("views"_a = fold.images, "rms_px"_a = fold.rms_px, "corners"_a = fold.corners,
                                "training_rms_px"_a = fold.training_rms_px, "training_corners"_a = fold.training_corners));
        return py::dict("views_per_fold"_a = h->views_per_fold, "folds"_a = folds, "per_view_rms_px"_a = h->per_view_rms_px,
                        "rms_px"_a = h->rms_px, "corners"_a = h->corners, "training_rms_px"_a = h->training_rms_px,
                        "training_corners"_a = h->training_corners);
      },
      "Every view held out once (holdout_folds=K): dict views_per_fold, folds (per fold: views, rms_px, corners, "
      "training_rms_px, training_corners), per_view_rms_px, rms_px (every fold's held-out corners), corners, "
      "training_rms_px, training_corners; None unless asked.");
  cls.def_property_readonly(
      "cross_validation",
      [record](const Holder& holder) -> py::object {
        const auto& c = record(holder).cross_validation;
        if (!c) return py::none();
        py::dict out = DiffDict(c->diff);
        out["halves"] = py::make_tuple(c->halves[0], c->halves[1]);
        out["half_rms_px"] = py::make_tuple(c->half_rms_px[0], c->half_rms_px[1]);
        out["aligned_at_boards"] =
            c->diff_aligned_at_boards ? py::object(DiffDict(*c->diff_aligned_at_boards)) : py::none();
        return out;
      },
      "The two halves' comparison (cross_validate=True): dict halves, half_rms_px, distance_mm, rms_px, median_px, "
      "max_px, unaligned_rms_px, compared, aligned, aligned_at_mm, rotation_deg, translation_mm, aligned_at_boards "
      "(the same keys with one alignment fitted at the boards' median distance, as predicted_error; None where it "
      "could not be); None unless asked.");
  cls.def_property_readonly(
      "predicted_error",
      [record](const Holder& holder) {
        py::list out;
        for (const CalibrationRecord::PredictedErrorSummary& p : record(holder).predicted_error) {
          const bool infinite = p.distance_mm >= kInfinityMm;
          out.append(py::dict("distance_mm"_a = infinite ? HUGE_VAL : p.distance_mm,
                              "n_rim_radii"_a = infinite ? HUGE_VAL : p.n_rim_radii, "median_px"_a = p.median_px,
                              "max_px"_a = p.max_px, "field_pixels"_a = p.field_pixels,
                              "unpredicted_pixels"_a = p.unpredicted_pixels,
                              "in_camera_frame_median_px"_a = p.in_camera_frame_median_px,
                              "in_camera_frame_max_px"_a = p.in_camera_frame_max_px,
                              "aligned_at_mm"_a = PythonDistanceMm(p.aligned_at_mm)));
        }
        return out;
      },
      "The predicted projection error per distance: list of dicts (distance_mm (inf for infinity), n_rim_radii, "
      "median_px, max_px (after the rigid alignment fitted at aligned_at_mm, the boards' median distance, as "
      "diff(align_at_mm=...)), field_pixels, unpredicted_pixels, in_camera_frame_median_px, in_camera_frame_max_px "
      "(points held in the camera's frame), aligned_at_mm (nan: fitted at each distance: an older file, or too few "
      "field pixels project at the boards' distance)).");
  cls.def(
      "to_json", [record](const Holder& holder) { return CalibrationJsonText(record(holder)); },
      "The text of calibration.json.");
}

PyDetections Detect(const py::object& target_arg, const py::object& images_arg, const py::object& guess, bool refine,
                    bool refine_checkerboards, bool checkerboard_edges, bool rim_circles, int threads,
                    py::object progress) {
  const PyTarget target = TargetOf(target_arg);
  const ImageInput input = ImagesOf(images_arg);
  DetectionOptions options;
  std::string guess_name;
  options.guess = GuessOf(guess, &guess_name, nullptr);
  options.refine = refine;
  options.refine_checkerboards = refine_checkerboards;
  options.checkerboard_edges = checkerboard_edges;
  options.rim_circles = rim_circles;
  options.threads = ThreadsOf(threads);
  options.progress = ForwardProgress(std::move(progress));
  DetectedImages found = RunReleased([&] {
    return input.paths.empty() ? DetectImages(target.board, input.images, options)
                               : DetectImageFiles(target.board, input.paths, input.source, options);
  });
  found.detections.target_spec = target.spec_path;
  return {std::move(found.detections), std::move(found.rim_circles), std::move(found.warnings)};
}

std::set<std::string> FixedOf(const py::handle& fixed) {
  std::set<std::string> blocks;
  if (py::isinstance<py::str>(fixed)) {  // "lens,m" as the CLI's --fix
    std::stringstream text(fixed.cast<std::string>());
    for (std::string block; std::getline(text, block, ',');)
      if (!block.empty()) blocks.insert(block);
    return blocks;
  }
  if (!py::isinstance<py::iterable>(fixed))
    throw InputError("fixed: expected block names (a list of str, or \"a,b\"), got " + TypeName(fixed));
  for (const py::handle block : fixed) {
    if (!py::isinstance<py::str>(block)) throw InputError("fixed: expected block names (str), got " + TypeName(block));
    blocks.insert(block.cast<std::string>());
  }
  return blocks;
}

// None, a dict name -> one std, or the CLI's "name=value,..." text; both read through
// the CLI's parser, so a bad entry gets its message.
DesignTolerances TolerancesOf(const py::handle& tolerances) {
  if (tolerances.is_none()) return {};
  if (py::isinstance<py::str>(tolerances)) return ParseDesignTolerances(tolerances.cast<std::string>(), "tolerances");
  if (!py::isinstance<py::dict>(tolerances))
    throw InputError("tolerances: expected a dict name -> std, got " + TypeName(tolerances));
  std::string text;
  for (const auto& [name, value] : py::reinterpret_borrow<py::dict>(tolerances))
    text += std::string(py::str(name)) + "=" + std::string(py::str(value)) + ",";
  return ParseDesignTolerances(text, "tolerances");
}

PyCalibration Calibrate(const py::object& target_arg, const py::object& images, const py::object& detections,
                        const py::object& guess, const std::string& profile, const py::object& fixed, double loss_px,
                        int max_iterations, int detection_passes, int threads, bool leave_one_out,
                        const py::object& tolerances, const std::vector<double>& distances_mm,
                        const std::vector<double>& distances_n, double max_predicted_error_px, double rim_field_deg,
                        int holdout, int holdout_folds, bool cross_validate, double cross_validation_distance_mm,
                        bool board_warp, bool view_weights, std::optional<bool> checkerboard_edges,
                        const py::object& knots, const std::string& lens, const std::string& tangential,
                        const std::string& board_relief, py::object progress) {
  CalibrationInput input;
  PyTarget target = TargetOf(target_arg);
  input.target = std::move(target.board);
  input.target_name = target.spec_path.empty() ? "target" : target.spec_path;
  input.guess = GuessOf(guess, &input.guess_name, &input.guess_tolerances);
  ImageInput image_input;
  if (!images.is_none()) {
    image_input = ImagesOf(images);
    input.image_paths = image_input.paths;
    input.images = image_input.images;
    input.source = image_input.source;
  }
  if (!detections.is_none()) {
    if (py::isinstance<PyDetections>(detections)) {
      input.detections = detections.cast<const PyDetections&>().set;
      input.source = "detections";
    } else if (IsPath(detections)) {
      input.source = PathOf(detections);
      input.detections = ReadDetections(input.source);
    } else {
      throw InputError("detections: expected an omnical.Detections or the path of a detections file, got " + TypeName(detections));
    }
  }
  CalibrationOptions options;
  options.profile = profile;
  options.fixed = FixedOf(fixed);
  options.loss_px = loss_px;
  options.max_iterations = max_iterations;
  options.detection_passes = detection_passes;
  options.threads = ThreadsOf(threads);
  options.leave_one_out = leave_one_out;
  options.tolerances = TolerancesOf(tolerances);
  options.distances_mm = distances_mm;
  options.distances_n = distances_n;
  options.max_predicted_error_px = max_predicted_error_px;
  options.rim_field_deg = rim_field_deg;
  options.holdout_views = holdout;
  options.holdout_folds = holdout_folds;
  options.board_warp = board_warp;
  options.view_weights = view_weights;
  options.checkerboard_edges = checkerboard_edges;
  if (py::isinstance<py::str>(knots)) {
    options.knots = ParseKnotCount(knots.cast<std::string>(), "knots");
  } else if (py::isinstance<py::int_>(knots) && !py::isinstance<py::bool_>(knots)) {
    options.knots = knots.cast<int>();
  } else {
    throw InputError("knots: expected a knot count (4..16) or 'auto', got " + TypeName(knots));
  }
  options.lens = lens;
  options.tangential = tangential;
  options.board_relief = board_relief;
  options.cross_validate = cross_validate;
  options.cross_validation_distance_mm = cross_validation_distance_mm;
  options.progress = ForwardProgress(std::move(progress));
  PyCalibration out{RunReleased([&] { return omnical::Calibrate(input, options); }), !input.detections, options,
                    std::move(input.images)};
  out.report_options.progress = nullptr;
  return out;
}

void Save(const PyCalibration& calibration, const py::object& out_dir, bool report) {
  const std::filesystem::path dir(PathOf(out_dir));
  GilReleased release;  // the report's figures take a moment
  CreateOutputDirectory(dir.string());
  SaveSensorYaml(calibration.result.sensor, (dir / "sensor.yaml").string());
  if (calibration.detected) WriteDetections(calibration.result.detections, (dir / "detections.json").string());
  WriteCalibrationJson(calibration.result.record, (dir / "calibration.json").string());
  if (report)
    WriteCalibrationReport((dir / "report").string(), calibration.result, calibration.report_options, calibration.images);
}

// Kalibr's field names in the target factories' messages, as Python's argument names.
template <typename Make>
PyTarget MakeTarget(Make make) {
  try {
    return {make(), ""};
  } catch (const std::invalid_argument& error) {
    std::string message = error.what();
    const std::pair<std::string, std::string> kNames[] = {{"tagSpacing", "spacing_ratio"}, {"tagFamily", "family"}};
    for (const auto& [kalibr, python] : kNames)
      if (message.rfind(kalibr + ":", 0) == 0) message = python + message.substr(kalibr.size());
    throw InputError(message);
  }
}

void Require(bool ok, const std::string& message) {
  if (!ok) throw InputError(message);
}

void BindTarget(py::module_& m) {
  py::class_<PyTarget>(m, "Target", R"(A planar calibration target (calib/target.h): an aprilgrid or a checkerboard.

Board frame: origin at the bottom-left tag's bottom-left black corner (checkerboard: the
bottom-left inner corner), x right along columns, y up along rows, z out of the printed
face, mm. Corner ids: aprilgrid 4 * tag_id + k (k = 0 bottom-left, 1 bottom-right,
2 top-right, 3 top-left of the black square); checkerboard row * cols + col.)")
      .def_static(
          "load", [](const py::object& path) { return TargetOf(path); }, "path"_a,
          "Reads a Kalibr-style target spec (YAML, sizes in metres). Raises InputError 'file: field: problem'.")
      .def_static(
          "aprilgrid",
          [](int cols, int rows, double tag_size_mm, double spacing_ratio, const std::string& family, int code_offset) {
            Require(cols >= 1 && cols <= 10000, "cols: must be a whole number >= 1");
            Require(rows >= 1 && rows <= 10000, "rows: must be a whole number >= 1");
            Require(tag_size_mm > 0.0 && std::isfinite(tag_size_mm), "tag_size_mm: must be > 0");
            Require(code_offset >= 0, "code_offset: must be a whole number >= 0");
            return MakeTarget([&] { return CalibrationTarget::AprilGrid(cols, rows, tag_size_mm, spacing_ratio, family, code_offset); });
          },
          "cols"_a, "rows"_a, "tag_size_mm"_a, "spacing_ratio"_a, "family"_a = "tag36h11", "code_offset"_a = 0,
          "An aprilgrid of cols x rows tags of tag_size_mm (the black square's edge), gaps of spacing_ratio x tag size; "
          "family tag36h11 or tagStandard41h12, tag ids from code_offset (Kalibr's codeOffset).")
      .def_static(
          "checkerboard",
          [](int cols, int rows, double col_spacing_mm, double row_spacing_mm) {
            Require(cols >= 2 && cols <= 10000, "cols: must be a whole number >= 2");
            Require(rows >= 2 && rows <= 10000, "rows: must be a whole number >= 2");
            Require(col_spacing_mm > 0.0 && std::isfinite(col_spacing_mm), "col_spacing_mm: must be > 0");
            Require(row_spacing_mm > 0.0 && std::isfinite(row_spacing_mm), "row_spacing_mm: must be > 0");
            return MakeTarget([&] { return CalibrationTarget::Checkerboard(cols, rows, col_spacing_mm, row_spacing_mm); });
          },
          "cols"_a, "rows"_a, "col_spacing_mm"_a, "row_spacing_mm"_a,
          "A checkerboard of cols x rows inner corners, squares col_spacing_mm wide and row_spacing_mm high.")
      .def_property_readonly(
          "type", [](const PyTarget& t) { return t.board.type() == CalibrationTarget::Type::kAprilGrid ? "aprilgrid" : "checkerboard"; },
          "'aprilgrid' or 'checkerboard'.")
      .def_property_readonly("cols", [](const PyTarget& t) { return t.board.cols(); }, "Tags (aprilgrid) or inner corners (checkerboard) per row.")
      .def_property_readonly("rows", [](const PyTarget& t) { return t.board.rows(); }, "Tags or inner corners per column.")
      .def_property_readonly("family", [](const PyTarget& t) { return t.board.family(); }, "The tag family (aprilgrid; '' for a checkerboard).")
      .def_property_readonly("code_offset", [](const PyTarget& t) { return t.board.code_offset(); }, "The first tag's id (aprilgrid).")
      .def_property_readonly("tag_size_mm", [](const PyTarget& t) { return t.board.tag_size_mm(); }, "The black square's edge (aprilgrid; mm).")
      .def_property_readonly("spacing_ratio", [](const PyTarget& t) { return t.board.spacing_ratio(); }, "Gap between tags / tag size (aprilgrid).")
      .def_property_readonly(
          "min_mm", [](const PyTarget& t) { return py::make_tuple(t.board.min_mm().x(), t.board.min_mm().y()); },
          "The printed board's lower-left corner in the board frame, margins included (x, y) mm.")
      .def_property_readonly(
          "max_mm", [](const PyTarget& t) { return py::make_tuple(t.board.max_mm().x(), t.board.max_mm().y()); },
          "The printed board's upper-right corner (x, y) mm.")
      .def_property_readonly("spec_path", [](const PyTarget& t) { return t.spec_path; },
                             "The spec file it was read from ('' when built in code).")
      .def(
          "points",
          [](const PyTarget& t) {
            const std::vector<TargetCorner>& corners = t.board.corners();
            std::vector<std::int32_t> ids;
            Eigen::Matrix3Xd points(3, corners.size());
            for (size_t i = 0; i < corners.size(); ++i) ids.push_back(corners[i].id), points.col(i) = corners[i].point_in_target;
            return py::make_tuple(VectorArray(std::move(ids)), RowsArrayOf<3>(std::move(points)));
          },
          "The corners: (ids (N,) int32, points (N, 3) float64, board frame, mm, z = 0).")
      .def(
          "write_png",
          [](const PyTarget& t, const py::object& path, double dpi) {
            Require(dpi >= 10.0 && dpi <= 2400.0, "dpi: must lie in [10, 2400]");
            t.board.WritePng(PathOf(path), dpi);
          },
          "path"_a, "dpi"_a = 300.0, "Writes the printable board as a PNG at true scale: dpi dots per inch (as `omnical target`).")
      .def(
          "write_svg", [](const PyTarget& t, const py::object& path) { t.board.WriteSvg(PathOf(path)); }, "path"_a,
          "Writes the printable board as SVG with its physical size (mm).")
      .def(
          "write_pdf", [](const PyTarget& t, const py::object& path) { t.board.WritePdf(PathOf(path)); }, "path"_a,
          "Writes the printable board as a one-page PDF with its physical size.")
      .def("__repr__", [](const PyTarget& t) {
        const Eigen::Vector2d size = t.board.max_mm() - t.board.min_mm();
        return "<omnical.Target " + std::string(t.board.type() == CalibrationTarget::Type::kAprilGrid ? "aprilgrid " : "checkerboard ") +
               std::to_string(t.board.cols()) + "x" + std::to_string(t.board.rows()) + ", " + std::to_string(t.board.corners().size()) +
               " corners, " + std::to_string(static_cast<int>(std::lround(size.x()))) + " x " +
               std::to_string(static_cast<int>(std::lround(size.y()))) + " mm>";
      });
}

void BindDetections(py::module_& m) {
  py::class_<CalibrationWarning>(m, "CalibrationWarning", "Something a detection or calibration found questionable without failing.")
      .def_property_readonly(
          "code", [](const CalibrationWarning& w) { return WarningCodeName(w.code); },
          "What kind: image_unreadable, image_size_differs, checkerboard_refused, view_skipped, tolerance_not_applicable, "
          "view_left_out, sensor_invalid, not_converged, free_gauge, weakly_determined, one_distance, tolerance_conflict, "
          "tolerance_note, predicted_error_unknown, predicted_error_high, held_out_worse, knot_count_replaced, "
          "lens_not_chosen, tangential_not_fitted, board_screen_stopped, image_rim_not_used, profile_not_chosen.")
      .def_readonly("subject", &CalibrationWarning::subject, "The image or parameter it concerns ('' for the whole run).")
      .def_readonly("text", &CalibrationWarning::text, "The one-line message (what the CLI prints).")
      .def("__repr__", [](const CalibrationWarning& w) { return "<omnical.CalibrationWarning " + std::string(WarningCodeName(w.code)) + ": " + w.text + ">"; });

  py::class_<RimCircle>(m, "RimCircle", "The mirror's rim in an image: the circle where the bright mirror disc ends.")
      .def_property_readonly("centre_px", [](const RimCircle& c) { return py::make_tuple(c.centre_px.x(), c.centre_px.y()); }, "(u, v) px.")
      .def_readonly("radius_px", &RimCircle::radius_px, "Radius (px).")
      .def_readonly("inlier_fraction", &RimCircle::inlier_fraction, "Fraction of the 720 rays that agree with the circle.")
      .def_readonly("rms_px", &RimCircle::rms_px, "RMS of the inliers about the circle (px).");

  py::class_<ImageDetections>(m, "ImageDetections", "The target's corners found in one image.")
      .def_readonly("image", &ImageDetections::image, "The image's path as given (or its name / index for arrays).")
      .def_property_readonly(
          "ids",
          [](const ImageDetections& d) {
            std::vector<std::int32_t> ids;
            for (const CornerObservation& c : d.corners) ids.push_back(c.id);
            return VectorArray(std::move(ids));
          },
          "Corner ids (N,) int32 (Target.points' ids).")
      .def_property_readonly(
          "pixels",
          [](const ImageDetections& d) {
            std::vector<Eigen::Vector2d> pixels;
            for (const CornerObservation& c : d.corners) pixels.push_back(c.pixel);
            return PointsArray(pixels);
          },
          "Corner pixels (N, 2) float64, (u, v); the centre of pixel (0, 0) at (0, 0).")
      .def_property_readonly(
          "unrefined",
          [](const ImageDetections& d) {
            py::array_t<bool> mask(static_cast<py::ssize_t>(d.corners.size()));
            for (size_t i = 0; i < d.corners.size(); ++i) mask.mutable_at(i) = d.corners[i].unrefined;
            return mask;
          },
          "(N,) bool: sub-pixel refinement failed (the detector's own position; calibrate leaves these out).")
      .def("__len__", [](const ImageDetections& d) { return d.corners.size(); });

  py::class_<PyDetections>(m, "Detections", "Detected corners per image: what `omnical detect` writes (detections.json).")
      .def_static(
          "load", [](const py::object& path) { return PyDetections{ReadDetections(PathOf(path)), {}, {}}; }, "path"_a,
          "Reads a detections file (JSON). Raises InputError naming the file and entry.")
      .def(
          "save", [](const PyDetections& d, const py::object& path) { WriteDetections(d.set, PathOf(path)); }, "path"_a,
          "Writes detections.json as `omnical detect` does (atomically).")
      .def_property_readonly("images", [](const PyDetections& d) { return d.set.images; }, "list of ImageDetections, one per image read.")
      .def_property_readonly(
          "image_size", [](const PyDetections& d) { return py::make_tuple(d.set.image_width_px, d.set.image_height_px); },
          "(width, height) px of the images.")
      .def_property_readonly("target_spec", [](const PyDetections& d) { return d.set.target_spec; }, "The target spec file the ids refer to.")
      .def_property_readonly("warnings", [](const PyDetections& d) { return d.warnings; },
                             "list of CalibrationWarning: images skipped, grids refused (empty when loaded).")
      .def_property_readonly("rim_circles", [](const PyDetections& d) { return d.rim_circles; },
                             "list of RimCircle of the images where one was found (rim_circles=True).")
      .def("__len__", [](const PyDetections& d) { return d.set.images.size(); });

  m.def("detect", &Detect, "target"_a, "images"_a, py::kw_only(), "guess"_a = py::none(), "refine"_a = true,
        "refine_checkerboards"_a = false, "checkerboard_edges"_a = false, "rim_circles"_a = false, "threads"_a = 0, "progress"_a = py::none(),
        R"(Detects the target's corners in omni images (as `omnical detect`) -> Detections.

target: a Target or the path of a target spec. images: a directory or glob pattern
(as --images), a list of paths, a list of uint8 arrays (grey, BGR or BGRA; named by
index) or a dict name -> array. guess: a Sensor or a sensor file; aprilgrid tags are
then re-detected in virtual views and refined through it. refine: sub-pixel refinement
of aprilgrid corners and of checkerboard corners on grid steps of 20 px and more;
refine_checkerboards: of every checkerboard corner, small squares too. checkerboard_edges:
with a guess, every checkerboard corner refined by its edges instead (--checkerboard-edges). rim_circles:
also find each image's mirror rim. threads: 0 for all cores. progress(stage, done,
total): return False to cancel. Unreadable images are skipped with a warning; raises
InputError if none could be read.)");
}

void BindCalibration(py::module_& m) {
  py::class_<ParameterEstimate>(m, "Parameter", "A fitted parameter: value, one standard deviation, held or not.")
      .def_readonly("name", &ParameterEstimate::name, "Name with its unit (fx_px, m_mm, tilt_x_deg, ...).")
      .def_readonly("value", &ParameterEstimate::value, "The fitted value.")
      .def_readonly("std", &ParameterEstimate::std, "One standard deviation (0 if fixed, NaN if undetermined).")
      .def_readonly("fixed", &ParameterEstimate::fixed, "Held constant in the fit.")
      .def("__repr__", [](const ParameterEstimate& p) {
        return "<omnical.Parameter " + p.name + " = " + std::to_string(p.value) + (p.fixed ? " (fixed)>" : " +- " + std::to_string(p.std) + ">");
      });

  py::class_<CalibrationRecord> record(m, "CalibrationRecord", "What calibration.json holds (calib/calibration_record.h).");
  AddRecordFields(record, [](const CalibrationRecord& r) -> const CalibrationRecord& { return r; });
  record.def_readonly("warnings", &CalibrationRecord::warnings, "The warnings' texts (list of str).")
      .def(
          "save", [](const CalibrationRecord& r, const py::object& path) { WriteCalibrationJson(r, PathOf(path)); }, "path"_a,
          "Writes calibration.json (atomically).");
  m.def(
      "load_calibration", [](const py::object& path) { return ReadCalibrationJson(PathOf(path)); }, "path"_a,
      "Reads a calibration.json back -> CalibrationRecord. Raises InputError 'path: field: problem'.");

  py::class_<PyCalibration> result(m, "CalibrationResult", R"(A calibration: the fitted sensor, the record (as calibration.json; its fields
are also attributes here), the warnings with their codes, the views and residuals.)");
  AddRecordFields(result, [](const PyCalibration& c) -> const CalibrationRecord& { return c.result.record; });
  result.def_property_readonly("sensor", [](const PyCalibration& c) { return c.result.sensor; }, "The fitted Sensor.")
      .def_property_readonly("record", [](const PyCalibration& c) { return c.result.record; }, "The CalibrationRecord (calibration.json).")
      .def_property_readonly("warnings", [](const PyCalibration& c) { return c.result.warnings; },
                             "list of CalibrationWarning (code, subject, text): detection's and the fit's, in order.")
      .def_property_readonly(
          "detections", [](const PyCalibration& c) -> py::object {
            if (!c.detected) return py::none();
            return py::cast(PyDetections{c.result.detections, {}, {}});
          },
          "Every corner detected here (Detections; None when calibrated from detections).")
      .def_property_readonly("views", [](const PyCalibration& c) { return PyDetections{c.result.views, {}, {}}; },
                             "The views given to the fit (Detections), in the fit's order.")
      .def_property_readonly(
          "residuals",
          [](const PyCalibration& c) {
            py::dict out;
            const auto& images = c.result.views.images;
            for (size_t v = 0; v < images.size() && v < c.result.fit.residuals_px.size(); ++v) {
              std::vector<std::int32_t> ids;
              for (const CornerObservation& corner : images[v].corners) ids.push_back(corner.id);
              out[py::str(images[v].image)] =
                  py::make_tuple(VectorArray(std::move(ids)), PointsArray(c.result.fit.residuals_px[v]));
            }
            return out;
          },
          "dict view -> (ids (N,) int32, residual_px (N, 2) float64): predicted - observed per corner, NaN where "
          "the corner was dropped or the view left out.")
      .def_property_readonly(
          "predicted_error_maps",
          [](const PyCalibration& c) {
            py::list out;
            for (size_t k = 0; k < c.result.predicted.size(); ++k) {
              const PredictedError& map = c.result.predicted[k];
              std::vector<double> std_px = map.std_px;
              out.append(py::dict("label"_a = k < c.result.distance_labels.size() ? c.result.distance_labels[k] : "",
                                  "distance_mm"_a = PythonDistanceMm(map.distance_mm),
                                  "pixels"_a = PointsArray(map.pixels), "std_px"_a = VectorArray(std::move(std_px))));
            }
            return out;
          },
          "The predicted projection error maps (the report's figures): list of dicts (label, distance_mm, pixels "
          "(N, 2), std_px (N,), NaN where the point does not project).")
      .def(
          "summary", [](const PyCalibration& c) { return CalibrationSummaryText(c.result); },
          "The lines `omnical calibrate` prints (str): RMS, parameters with stds, warp, held-out and halves.")
      .def("save", &Save, "out_dir"_a, "report"_a = true,
           "Writes what `omnical calibrate --out` writes: sensor.yaml, calibration.json, detections.json (when detected "
           "here) and, with report=True, the report figures (out_dir/report/*.png).");

  m.def("calibrate", &Calibrate, "target"_a, "images"_a = py::none(), py::kw_only(), "detections"_a = py::none(),
        "guess"_a = py::none(), "profile"_a = "", "fixed"_a = py::tuple(), "loss_px"_a = 1.0, "max_iterations"_a = 200,
        "detection_passes"_a = 2, "threads"_a = 0, "leave_one_out"_a = false, "tolerances"_a = py::none(),
        "distances_mm"_a = std::vector<double>(), "distances_n"_a = std::vector<double>(),
        "max_predicted_error_px"_a = 0.3, "rim_field_deg"_a = kDefaultRimFieldDeg, "holdout"_a = 0,
        "holdout_folds"_a = 0, "cross_validate"_a = false, "cross_validation_distance_mm"_a = 0.0,
        "board_warp"_a = true, "view_weights"_a = false, "checkerboard_edges"_a = py::none(), "knots"_a = 0,
        "lens"_a = "", "tangential"_a = "", "board_relief"_a = "", "progress"_a = py::none(),
        R"(Calibrates the sensor (as `omnical calibrate`) -> CalibrationResult.

target: a Target or a spec path. Corners: images (as detect(): a directory or glob, a
list of paths or arrays, a dict name -> array) or detections (a Detections or a
detections file), exactly one. guess: a Sensor or a sensor file (a file also brings its
design tolerances, as --sensor); without one the fit starts from the mirror's rim circle
(rim_field_deg: the rim ray's angle from the axis; lens: the lens it starts, 'auto'
('' too: chosen by held-out folds, result.lens_choice; the orthographic with under 4
views), 'orthographic' or 'pinhole'). tangential: a pinhole's p1, p2, 'off' (held; '' with
a guess), 'on' (fitted) or 'auto' ('' without a guess: fitted where that predicts held-out
folds better, result.tangential_choice). profile: mirror family to fit
(one of omnical.PROFILES but tabulated; '' the guess's; without a guess 'auto', '' too:
the polynomial or the even asphere by held-out folds, result.profile_choice, then through
the orthographic lens a spline's knot count or none, result.knot_choice; the
polynomial with under 4 views). fixed: blocks held (lens,
lens_scale, principal_point, distortion, tangential, m, tilt, decenter, shape, poses; a list or 'a,b').
loss_px: Huber scale (0: least squares). detection_passes: 2 re-detects through the
first fit, 3 (aprilgrids) once more through the second (checkerboards: one pass more
after boards the last found; result.detection_passes counts them). threads: detection, board checks and the fit's Jacobians, 0 for all cores
(the same result for any count). leave_one_out: also fit without each view.
tolerances: design tolerances (dict name -> one std, or 'name=value,...').
distances_mm / distances_n: where to predict the projection error (mm, or rim radii);
max_predicted_error_px: warn above it. holdout: K views (spread evenly) kept out of the
fit and evaluated with the sensor held (result.holdout). holdout_folds: every view held
out once, K at a time, one calibration per fold (result.holdout_folds; the result is the
full set's). cross_validate: each half of the
views calibrated and compared at cross_validation_distance_mm (0: the first distance
asked, else 2000) after the best rigid alignment (result.cross_validation). board_warp:
fit the board's out-of-plane warp (result.board_warp, mm; the default, False holds the
board flat). board_relief: each corner's own out-of-plane offset on top of the warp, 'off',
'on' (fitted) or 'auto' ('' without a guess: fitted where that predicts held-out folds
better, result.relief_choice; result.board_warp['relief']). view_weights: weight
each view's corners by its own noise, estimated from its residuals
(result.per_view_weight). checkerboard_edges: None (default) refines a checkerboard's
corners through the first fit by their edges, every one, where that applies; True asks
for it (--checkerboard-edges: refused where it cannot apply); False refines them by
cornerSubPix on squares of 20 px and more instead (--checkerboard-subpixel). knots: the spline
mirror's knot count (profile='spline'): 0 the guess's (6 converted), 4..16, or 'auto' to
choose it by held-out folds (result.knot_choice).
progress(stage, done, total): False cancels.
Raises InputError with the library's message (too few views, a bad file, a bad value).)");

  m.def(
      "diff",
      [](const py::object& a, const py::object& b, double distance_mm, const py::object& field, double step_px,
         bool align, const std::optional<double>& align_at_mm) {
        // A Sensor, a sensor file, or calibrate's output directory (its sensor.yaml).
        const auto sensor_of = [](const py::object& given, const char* name) {
          if (py::isinstance<Sensor>(given)) return given.cast<Sensor>();
          if (!IsPath(given))
            throw InputError(std::string(name) + ": expected an omnical.Sensor, a sensor file or a calibration directory, got " +
                             TypeName(given));
          std::string path = PathOf(given);
          if (std::filesystem::is_directory(path)) path = (std::filesystem::path(path) / "sensor.yaml").string();
          return LoadSensorYaml(path);
        };
        const Sensor reference = sensor_of(a, "a"), other = sensor_of(b, "b");
        std::optional<DetectionSet> detections;
        if (py::isinstance<PyDetections>(field)) {
          detections = field.cast<const PyDetections&>().set;
        } else if (IsPath(field)) {
          detections = ReadDetections(PathOf(field));
        } else if (!field.is_none()) {
          throw InputError("field: expected an omnical.Detections, a detections file or None, got " + TypeName(field));
        }
        const ProjectionDiff diff = RunReleased([&] {
          return CompareProjections(reference, other, ComparisonField(reference, detections ? &*detections : nullptr, step_px),
                                    distance_mm, align, align_at_mm.value_or(NAN));
        });
        py::dict out = DiffDict(diff);
        out["pixels"] = PointsArray(diff.pixels);
        out["difference_px"] = PointsArray(diff.difference_px);
        return out;
      },
      "a"_a, "b"_a, py::kw_only(), "distance_mm"_a = 2000.0, "field"_a = py::none(), "step_px"_a = 16.0,
      "align"_a = true, "align_at_mm"_a = py::none(),
      R"(Compares two calibrations of one camera (as `omnical diff`) -> dict.

a, b: a Sensor, a sensor file or calibrate's output directory. The points distance_mm
along each field pixel's ray through a (from its reflection point; a large value such as
1e8 for infinity), moved by the rigid motion that best aligns them (align=False: none),
projected through b. That motion is fitted at distance_mm, or at align_at_mm and applied
at distance_mm (one motion for a scene that spans distances: align_at_mm the boards'
distance, as calibrate's predicted_error). field: Detections or a detections file whose
corners' annulus is compared, None for every pixel of a's mirror; step_px apart. Returns
rms_px, median_px, max_px, unaligned_rms_px (both over the compared pixels), compared,
moved_off_mirror (aligned elsewhere, points the motion moved past b's rim: not compared),
aligned, aligned_at_mm (inf for infinity), rotation_deg, translation_mm, distance_mm,
pixels (N, 2) and difference_px (N, 2; NaN where not compared).)");
}

}  // namespace

void BindCalib(py::module_& m) {
  BindTarget(m);
  BindDetections(m);
  BindCalibration(m);
}

}  // namespace omnical::python
