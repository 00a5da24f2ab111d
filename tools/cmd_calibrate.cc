// omnical calibrate: the bundle fit of the non-central model from images (detected here)
// or detections, starting from a sensor guess or, without one, from the mirror's rim
// circle -> sensor.yaml, calibration.json and a report of PNG figures. Everything is
// checked and computed before anything is written.
#include <nlohmann/json.hpp>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <algorithm>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

#include "calib/board_scale.h"
#include "calib/bundle_fit.h"
#include "calib/design_tolerances.h"
#include "calib/initial_sensor.h"
#include "calib/predicted_error.h"
#include "calib/rim_circle.h"
#include "model/atomic_write.h"
#include "model/input_error.h"
#include "tools/commands.h"
#include "tools/detect_images.h"
#include "calib/report/plot.h"

namespace omnical::cli {
namespace {

struct Options {
  std::string target_path, detections_path, images, sensor_path, profile, out_dir, fix;
  double rim_field_deg = kDefaultRimFieldDeg;
  int threads = 1;
  double loss_px = 1.0;
  int max_iterations = 200;
  bool leave_one_out = false;
  int detection_passes = 2;
  std::string tolerance;
  std::vector<double> distances_mm, distances_n;
  double max_predicted_error_px = 0.3;
};

std::set<std::string> SplitList(const std::string& text) {
  std::set<std::string> items;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ','))
    if (!item.empty()) items.insert(item);
  return items;
}

// A map of the predicted projection error over the observed field, one cell per grid pixel.
void WritePredictedErrorMap(const std::string& path, const Sensor& sensor, const PredictedError& map, double step_px,
                            double threshold_px, const std::string& label) {
  cv::Mat picture(sensor.image_height_px(), sensor.image_width_px(), CV_8UC3, cv::Scalar(30, 30, 30));
  // Colour scale from 0 to the larger of the worst value and the warning threshold, so a
  // map under the threshold never looks alarming.
  const double top = std::max(threshold_px, map.max_px);
  for (size_t k = 0; k < map.pixels.size(); ++k) {
    if (!std::isfinite(map.std_px[k])) continue;
    cv::Mat level(1, 1, CV_8U, cv::Scalar(static_cast<int>(std::lround(255.0 * std::min(1.0, map.std_px[k] / top)))));
    cv::Mat colour;
    cv::applyColorMap(level, colour, cv::COLORMAP_VIRIDIS);
    const cv::Vec3b c = colour.at<cv::Vec3b>(0, 0);
    const cv::Point2d corner(map.pixels[k].x() - 0.5 * step_px, map.pixels[k].y() - 0.5 * step_px);
    cv::rectangle(picture, cv::Rect2d(corner, cv::Size2d(step_px, step_px)), cv::Scalar(c[0], c[1], c[2]), cv::FILLED);
  }
  char text[200];
  std::snprintf(text, sizeof text, "predicted error at %s: median %.3f px, worst %.3f px", label.c_str(), map.median_px,
                map.max_px);
  cv::putText(picture, text, {10, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  std::snprintf(text, sizeof text, "colour: 0 (purple) to %.3f px (yellow); warning above %.2f px", top, threshold_px);
  cv::putText(picture, text, {10, 48}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  WritePng(path, picture);
}

void WriteReport(const std::filesystem::path& dir, const DetectionSet& detections, const FitResult& fit) {
  CreateOutputDirectory(dir);
  double worst = 0.0;
  std::vector<double> magnitudes;
  for (const auto& view : fit.residuals_px)
    for (const Eigen::Vector2d& r : view)
      if (std::isfinite(r.x())) magnitudes.push_back(r.norm()), worst = std::max(worst, r.norm());
  // Residual vectors on each image, scaled so the largest is ~40 px long.
  const double scale = worst > 0.0 ? std::pow(10.0, std::floor(std::log10(40.0 / worst))) : 1.0;
  cv::Mat coverage(detections.image_height_px, detections.image_width_px, CV_8UC3, cv::Scalar(30, 30, 30));
  for (size_t v = 0; v < detections.images.size(); ++v) {
    const ImageDetections& image = detections.images[v];
    cv::Mat picture = ReadImage(image.image, cv::IMREAD_COLOR);
    if (picture.empty()) picture = cv::Mat(detections.image_height_px, detections.image_width_px, CV_8UC3, cv::Scalar(40, 40, 40));
    for (size_t i = 0; i < image.corners.size(); ++i) {
      const cv::Point2d p(image.corners[i].pixel.x(), image.corners[i].pixel.y());
      cv::circle(coverage, p, 2, SeriesColor(static_cast<int>(v)), cv::FILLED);
      const Eigen::Vector2d& r = fit.residuals_px[v][i];
      if (!std::isfinite(r.x())) {
        cv::drawMarker(picture, p, cv::Scalar(0, 0, 255), cv::MARKER_TILTED_CROSS, 8, 1);  // dropped
        continue;
      }
      cv::circle(picture, p, 2, cv::Scalar(0, 200, 0), cv::FILLED);
      cv::line(picture, p, p + cv::Point2d(r.x(), r.y()) * scale, cv::Scalar(0, 140, 255), 1, cv::LINE_AA);
    }
    char legend[160];
    std::snprintf(legend, sizeof legend, "residuals x%g (orange), RMS %.3f px; red crosses: dropped", scale,
                  fit.per_view_rms_px[v]);
    cv::putText(picture, legend, {10, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
    WritePng((dir / ("residuals_view" + std::to_string(v) + ".png")).string(), picture);
  }
  cv::putText(coverage, "detected corners, one colour per view", {10, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.6,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  WritePng((dir / "coverage.png").string(), coverage);

  // Histogram of residual magnitudes and per-view RMS, drawn as steps.
  const int bins = 30;
  const double width = worst > 0.0 ? worst / bins : 1.0;
  std::vector<double> counts(bins, 0.0);
  for (double m : magnitudes) counts[std::min(bins - 1, static_cast<int>(m / width))] += 1.0;
  std::vector<double> x, y;
  for (int b = 0; b < bins; ++b) {
    x.insert(x.end(), {b * width, b * width, (b + 1) * width, (b + 1) * width});
    y.insert(y.end(), {0.0, counts[b], counts[b], 0.0});
  }
  PlotPanel histogram("Residual magnitudes", "|residual| (px)", "corners");
  histogram.series.push_back(PlotSeries("", x, y, SeriesColor(0)));
  WritePng((dir / "residual_histogram.png").string(), RenderPanel(histogram, 800, 500));
  x.clear(), y.clear();
  for (size_t v = 0; v < fit.per_view_rms_px.size(); ++v) {
    x.insert(x.end(), {v - 0.4, v - 0.4, v + 0.4, v + 0.4});
    y.insert(y.end(), {0.0, fit.per_view_rms_px[v], fit.per_view_rms_px[v], 0.0});
  }
  PlotPanel per_view("RMS reprojection error per view", "view", "RMS (px)");
  per_view.series.push_back(PlotSeries("", x, y, SeriesColor(1)));
  WritePng((dir / "per_view_rms.png").string(), RenderPanel(per_view, 800, 500));
}

// Drops corner ids the target does not have; throws if none is left.
// The detections without corners the target does not have and without corners marked
// unrefined (the detector's own position, ~5x worse than refined ones: unweighted among
// them they biased the mirror's size on renders); *unrefined counts the latter.
DetectionSet FittableCorners(const CalibrationTarget& target, const std::string& target_path, const std::string& source,
                             DetectionSet detections, int* unrefined) {
  std::set<int> ids;
  for (const TargetCorner& c : target.corners()) ids.insert(c.id);
  int matched = 0;
  *unrefined = 0;
  for (ImageDetections& image : detections.images) {
    image.corners.erase(std::remove_if(image.corners.begin(), image.corners.end(),
                                       [&](const CornerObservation& c) {
                                         if (!ids.count(c.id)) return true;
                                         ++matched;
                                         *unrefined += c.unrefined;
                                         return c.unrefined;
                                       }),
                        image.corners.end());
  }
  if (matched == 0) throw InputError(InputMessage(target_path, "", "the target spec matches no corner id in " + source));
  return detections;
}

// Targets whose distances from the lens span less than this ratio count as "one
// distance" (the warning above the fit's results).
constexpr double kOneDistanceRatio = 1.5;

struct UsableViews {
  DetectionSet detections;  // the views with a starting pose
  std::vector<TargetPose> poses;
  int observations = 0;  // corners
};

// Views with at least 4 corners and a pose through `start`; throws when they cannot
// determine the sensor.
UsableViews ViewsForFit(const Sensor& start, const CalibrationTarget& target, const DetectionSet& detections,
                        const std::string& source, bool quiet) {
  UsableViews views;
  views.detections = detections;
  views.detections.images.clear();
  for (const ImageDetections& image : detections.images) {
    TargetPose pose;
    if (image.corners.size() < 4 || !InitialTargetPose(start, target, image, &pose)) {
      if (!quiet) std::fprintf(stderr, "omnical: warning: %s: too few usable corners, view skipped\n", image.image.c_str());
      continue;
    }
    views.detections.images.push_back(image);
    views.poses.push_back(pose);
  }
  // Enough data for what is asked: 2 residuals per corner against 6 per view plus the
  // sensor's free parameters, and views that differ (one pose says nothing about the
  // mirror).
  for (const ImageDetections& image : views.detections.images) views.observations += static_cast<int>(image.corners.size());
  const int sensor_parameters = static_cast<int>(SensorParameters(start).size());
  const int view_count = static_cast<int>(views.detections.images.size());
  if (view_count < 3 || 2 * views.observations < 2 * (6 * view_count + sensor_parameters))
    throw InputError(InputMessage(source, "images",
                                  std::to_string(view_count) + " usable views with " + std::to_string(views.observations) +
                                      " corners are too few for the " + std::to_string(sensor_parameters) +
                                      " sensor parameters (need >= 3 views)"));
  double spread_deg = 0.0, spread_mm = 0.0;
  for (const TargetPose& pose : views.poses) {
    spread_deg = std::max(spread_deg, pose.camera_from_target_rotation.angularDistance(views.poses[0].camera_from_target_rotation) * 180.0 / M_PI);
    spread_mm = std::max(spread_mm, (pose.camera_from_target_translation_mm - views.poses[0].camera_from_target_translation_mm).norm());
  }
  if (spread_deg < 1.0 && spread_mm < 5.0)
    throw InputError(InputMessage(source, "images", "all views show the target at one pose: move it between images"));
  return views;
}

// The rim circle of the images a detections file names (the median over those that read).
std::optional<RimCircle> RimOfImages(const DetectionSet& detections) {
  std::vector<RimCircle> circles;
  for (const ImageDetections& image : detections.images) {
    const cv::Mat grey = ReadImage(image.image, cv::IMREAD_GRAYSCALE);
    if (grey.empty()) continue;
    if (auto circle = DetectRimCircle(grey)) circles.push_back(*circle);
  }
  return MedianRimCircle(circles);
}

void Run(const Options& options, const Context& context) {
  const CalibrationTarget target = CalibrationTarget::FromYaml(options.target_path);
  if (options.images.empty() == options.detections_path.empty())
    throw InputError("calibrate: give either --images (detect here) or --detections (from omnical detect)");
  std::optional<Sensor> given;
  if (!options.sensor_path.empty()) given = LoadSensorYaml(options.sensor_path);
  // Where the corners come from, named in messages.
  const std::string source = options.images.empty() ? options.detections_path : options.images;
  DetectionSet detections;
  std::optional<RimCircle> rim;
  if (!options.images.empty()) {
    ImageDetectionOptions detection;
    detection.guess = given ? &*given : nullptr;
    detection.rim_circles = !given;
    detection.threads = options.threads;
    detection.quiet = context.quiet;
    DetectedImages found = DetectImages(target, options.target_path, options.images, detection);
    detections = std::move(found.detections);
    if (!given) rim = MedianRimCircle(found.rim_circles);
  } else {
    detections = ReadDetections(options.detections_path);
    if (!given) rim = RimOfImages(detections);
  }
  // The starting sensor: the guess (in another profile family if asked), or, with no
  // guess, the rim circle of the images.
  std::string start;
  std::optional<Sensor> start_sensor;
  if (given) {
    start_sensor = options.profile.empty() ? *given : ConvertProfile(*given, options.profile);
    start = options.sensor_path + (options.profile.empty() ? "" : " as a " + options.profile + " mirror");
  } else {
    if (!rim)
      throw InputError(InputMessage(source, "images",
                                    "no mirror rim circle found to start from; give a sensor guess with --sensor"));
    const std::string profile = options.profile.empty() ? "polynomial" : options.profile;
    start_sensor = SensorFromRimCircle(*rim, detections.image_width_px, detections.image_height_px, profile, options.rim_field_deg);
    start = "rim circle, " + profile + " mirror, orthographic lens";
    if (!context.quiet)
      std::printf("rim circle: centre (%.2f, %.2f) px, radius %.2f px (%.0f%% of rays, %.2f px RMS)\n", rim->centre_px.x(),
                  rim->centre_px.y(), rim->radius_px, 100.0 * rim->inlier_fraction, rim->rms_px);
  }
  const Sensor& guess = *start_sensor;
  if (detections.image_width_px != guess.image_width_px() || detections.image_height_px != guess.image_height_px())
    throw InputError(InputMessage(source, "image_size",
                                  std::to_string(detections.image_width_px) + " x " + std::to_string(detections.image_height_px) +
                                      " differs from the sensor's " + std::to_string(guess.image_width_px()) + " x " +
                                      std::to_string(guess.image_height_px())));
  FitOptions fit_options = FitOptions::DefaultsFor(guess);
  for (const std::string& name : SplitList(options.fix)) fit_options.fixed.insert(name);
  fit_options.robust_loss_px = options.loss_px;
  fit_options.max_iterations = options.max_iterations;
  if (const std::string why = fit_options.Check(); !why.empty()) throw InputError(why);
  // Design tolerances: the guess file's, then --tolerance's (which win), per parameter.
  std::vector<std::string> warnings;
  if (given) {
    fit_options.tolerances = ExpandTolerances(ReadDesignTolerances(options.sensor_path, *given));
    // Converted to another family: the old family's shape tolerances do not apply.
    for (auto it = fit_options.tolerances.begin(); it != fit_options.tolerances.end();) {
      FitOptions one;
      one.tolerances = {*it};
      if (one.CheckFor(guess).empty()) {
        ++it;
        continue;
      }
      warnings.push_back(options.sensor_path + ": the tolerance on " + it->first + " does not apply to a " +
                         guess.profile_name() + " mirror and is not used");
      it = fit_options.tolerances.erase(it);
    }
  }
  for (const auto& [name, value] : ExpandTolerances(ParseDesignTolerances(options.tolerance, "--tolerance")))
    fit_options.tolerances[name] = value;
  if (const std::string why = fit_options.CheckFor(guess); !why.empty()) throw InputError("--tolerance: " + why);
  // The tolerances stay centred on the start's values through every pass.
  for (const ParameterEstimate& p : SensorParameters(guess)) fit_options.design[p.name] = p.value;

  int unrefined = 0;
  UsableViews views = ViewsForFit(guess, target, FittableCorners(target, options.target_path, source, detections, &unrefined),
                                  source, context.quiet);
  std::optional<Sensor> refit_start;  // the previous pass's fit, where the last fit started
  FitResult fit = FitSensor(guess, target, views.detections, views.poses, fit_options);
  // Second detection pass (aprilgrid from images): the corners are refined in patches
  // through a sensor, and a tag's straight edges are straight there only as far as that
  // sensor is right. Through the design guess the patch edges bend, and the corners
  // carried a radius-dependent bias the mirror's size absorbed; re-detected through the
  // first fit they do not (30-view render: A 6 std off after one pass, 0.5 std after two;
  // tests/cli/calibrate_render_test.sh).
  const bool redetect = !options.images.empty() && target.type() == CalibrationTarget::Type::kAprilGrid;
  for (int pass = 2; redetect && pass <= options.detection_passes && fit.sensor; ++pass) {
    refit_start = *fit.sensor;
    ImageDetectionOptions detection;
    detection.guess = &*refit_start;
    detection.threads = options.threads;
    detection.quiet = context.quiet;
    detections = DetectImages(target, options.target_path, options.images, detection).detections;
    views = ViewsForFit(*refit_start, target, FittableCorners(target, options.target_path, source, detections, &unrefined),
                        source, context.quiet);
    fit = FitSensor(*refit_start, target, views.detections, views.poses, fit_options);
  }
  const Sensor& fit_start = refit_start ? *refit_start : guess;
  // Boards of another size than the target (a decoy the detector accepted, e.g. a window
  // of tiles that passed the continuation test) are refused through the fitted sensor and
  // the fit is repeated without them (calib/board_scale.h).
  std::map<std::string, std::string> wrongly_sized;  // image -> why its board was refused
  if (fit.sensor) {
    std::vector<size_t> refused;
    for (size_t v = 0; v < views.detections.images.size(); ++v) {
      if (!fit.view_left_out[v].empty()) continue;
      const BoardScale check = CheckBoardScale(*fit.sensor, target, views.detections.images[v], fit.poses[v], fit.sigma_px);
      if (!check.refused) continue;
      wrongly_sized[views.detections.images[v].image] = "the board " + check.reason;
      refused.push_back(v);
    }
    for (auto v = refused.rbegin(); v != refused.rend(); ++v) {
      views.observations -= static_cast<int>(views.detections.images[*v].corners.size());
      views.detections.images.erase(views.detections.images.begin() + *v);
      views.poses.erase(views.poses.begin() + *v);
    }
    if (!refused.empty()) {
      if (views.detections.images.size() < 3)
        throw InputError(InputMessage(source, "images",
                                      std::to_string(views.detections.images.size()) +
                                          " views are left once the boards of another size are refused (need >= 3)"));
      fit = FitSensor(fit_start, target, views.detections, views.poses, fit_options);
    }
  }
  const DetectionSet& usable = views.detections;
  const std::vector<TargetPose>& poses = views.poses;
  const int observations = views.observations;
  if (!fit.sensor) throw InputError(InputMessage(source, "", "the fit failed: " + fit.solver_report));
  const std::string why_invalid = ValidateSensorModel(fit.sensor->model());

  nlohmann::json result;
  result["rms_px"] = fit.rms_px;
  result["converged"] = fit.converged;
  result["outliers"] = fit.outliers;
  result["dropped"] = fit.dropped;
  result["unrefined_corners_left_out"] = unrefined;
  result["observations"] = fit.observations;
  result["solver_report"] = fit.solver_report;
  result["fixed_blocks"] = fit_options.fixed;
  result["robust_loss_px"] = fit_options.robust_loss_px;
  result["covariance_ok"] = fit.covariance_ok;
  result["start"] = start;
  result["detection_passes"] = refit_start ? options.detection_passes : 1;
  if (rim)
    result["rim_circle"] = {{"centre_px", {rim->centre_px.x(), rim->centre_px.y()}},
                            {"radius_px", rim->radius_px},
                            {"inlier_fraction", rim->inlier_fraction},
                            {"rms_px", rim->rms_px}};
  // Stability: the fit repeated without each image in turn; the spread of each parameter.
  if (options.leave_one_out) {
    std::map<std::string, std::vector<double>> folds;
    FitOptions quick = fit_options;
    quick.compute_covariance = false;
    for (size_t left_out = 0; left_out < usable.images.size(); ++left_out) {
      DetectionSet subset = usable;
      std::vector<TargetPose> subset_poses = poses;
      subset.images.erase(subset.images.begin() + left_out);
      subset_poses.erase(subset_poses.begin() + left_out);
      const FitResult fold = FitSensor(fit_start, target, subset, subset_poses, quick);
      for (const ParameterEstimate& p : fold.parameters) folds[p.name].push_back(p.value);
      if (!context.quiet) std::fprintf(stderr, "\rleave-one-out: %zu/%zu", left_out + 1, usable.images.size());
    }
    if (!context.quiet) std::fputc('\n', stderr);
    for (const auto& [name, values] : folds) {
      const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
      double mean = 0.0, square = 0.0;
      for (double v : values) mean += v;
      mean /= values.size();
      for (double v : values) square += (v - mean) * (v - mean);
      result["leave_one_out"][name] = {{"min", *lo}, {"max", *hi}, {"std", std::sqrt(square / values.size())}};
    }
  }
  if (!why_invalid.empty()) warnings.push_back("the fitted sensor fails validation: " + why_invalid);
  if (!fit.converged) warnings.push_back("the solver did not converge: " + fit.solver_report);
  if (!fit.covariance_ok) warnings.push_back("the parameters are not all determined by the data (a free gauge): fix one with --fix");
  // Weakly determined: the "dolly zoom" between fx and m is the usual one (the lens sees
  // the mirror under a small angle); fixing m from the design or fx from the lens helps.
  // Only scale-like parameters have a meaningful relative std (tilts, decenters, the
  // principal point and distortion are naturally near zero).
  auto shape_parameter = [](const std::string& name) {
    return name == "A_mm" || name == "B_mm" ||
           (name.size() >= 2 && name[0] == 'c' && std::isdigit(static_cast<unsigned char>(name[1])));
  };
  auto scale_like = [&](const std::string& name) {
    return name == "fx_px" || name == "fy_px" || name == "scale_px_per_mm" || name == "m_mm" || shape_parameter(name);
  };
  for (const ParameterEstimate& p : fit.parameters)
    if (!p.fixed && scale_like(p.name) && std::isfinite(p.std) && p.value != 0.0 && p.std > 0.05 * std::abs(p.value))
      warnings.push_back(p.name + " is weakly determined (std " + std::to_string(100.0 * p.std / std::abs(p.value)) +
                         (p.name == "fx_px" || p.name == "fy_px" || p.name == "m_mm"
                              ? "% of its value): fx and m trade off; fix m from the design (--fix m) or the lens scale, "
                                "or add views at more distances"
                              : "% of its value): views covering more of the mirror, at more distances, help"));
  // One distance: a non-central mirror's shape shows in how its image changes with the
  // object's distance (the viewpoints slide), so with every board at about the same range
  // the shape trades off against m and the lens scale.
  const bool shape_free = std::any_of(fit.parameters.begin(), fit.parameters.end(),
                                      [&](const ParameterEstimate& p) { return !p.fixed && shape_parameter(p.name); });
  double nearest_mm = HUGE_VAL, farthest_mm = 0.0;
  for (size_t v = 0; v < fit.poses.size(); ++v) {
    if (!fit.view_left_out[v].empty()) continue;  // its pose was not fitted
    nearest_mm = std::min(nearest_mm, fit.poses[v].camera_from_target_translation_mm.norm());
    farthest_mm = std::max(farthest_mm, fit.poses[v].camera_from_target_translation_mm.norm());
  }
  result["target_distance_mm"] = {{"nearest", nearest_mm}, {"farthest", farthest_mm}};
  if (shape_free && farthest_mm < kOneDistanceRatio * nearest_mm) {
    char text[300];
    std::snprintf(text, sizeof text,
                  "all targets are at one distance (%.0f-%.0f mm from the lens) while the mirror shape is free: the shape "
                  "is weakly determined; add views at least %.1fx nearer or farther, or fix it (--fix shape)",
                  nearest_mm, farthest_mm, kOneDistanceRatio);
    warnings.push_back(text);
  }
  // Views the fit left out, and why (their corners are in the report, marked dropped;
  // those of boards of another size are not in the report).
  for (const auto& [image, why] : wrongly_sized) {
    warnings.push_back(image + ": view left out of the fit: " + why);
    result["views_left_out"][image] = why;
  }
  for (size_t v = 0; v < usable.images.size(); ++v)
    if (!fit.view_left_out[v].empty()) {
      warnings.push_back(usable.images[v].image + ": view left out of the fit: " + fit.view_left_out[v]);
      result["views_left_out"][usable.images[v].image] = fit.view_left_out[v];
    }
  for (const std::string& conflict : fit.tolerance_conflicts) warnings.push_back(conflict);
  for (const std::string& note : fit.tolerance_notes) warnings.push_back(note);
  result["outlier_threshold_px"] = fit.outlier_threshold_px;
  for (size_t v = 0; v < usable.images.size(); ++v) result["per_view_outliers"][usable.images[v].image] = fit.per_view_outliers[v];
  result["sigma_px"] = fit.sigma_px;
  result["tolerances"] = fit_options.tolerances;
  result["rim_radius_mm"] = {{"guess", guess.rim_radius_mm()}, {"fitted", fit.sensor->rim_radius_mm()}};
  if (fit.covariance_ok) {
    result["covariance"]["names"] = fit.covariance_names;
    for (int r = 0; r < fit.covariance.rows(); ++r) {
      std::vector<double> row(fit.covariance.cols());
      for (int c = 0; c < fit.covariance.cols(); ++c) row[c] = fit.covariance(r, c);
      result["covariance"]["matrix"].push_back(row);
    }
  }
  // The error at the user's distances: the covariance through the projection over the
  // observed field (calib/predicted_error.h). Default: the corners' median distance from
  // their reflection points, and infinity.
  std::vector<PredictedError> predicted;
  std::vector<std::string> distance_labels;
  const double rim_mm = guess.rim_radius_mm();  // n counts the start's (design) rim radii
  constexpr double kMapStepPx = 16.0;
  if (fit.covariance_ok) {
    std::vector<double> distances = options.distances_mm;
    for (double n : options.distances_n) distances.push_back(n * rim_mm);
    if (distances.empty()) {
      if (const double median_mm = MedianCornerDistanceMm(*fit.sensor, target, usable, fit); std::isfinite(median_mm))
        distances.push_back(median_mm);
      distances.push_back(kInfinityMm);
    }
    DetectionSet fitted_views = usable;  // the field the fit saw: its fitted views
    fitted_views.images.clear();
    for (size_t v = 0; v < usable.images.size(); ++v)
      if (fit.view_left_out[v].empty()) fitted_views.images.push_back(usable.images[v]);
    const std::vector<Eigen::Vector2d> field = FieldPixels(*fit.sensor, FieldOfCorners(*fit.sensor, fitted_views), kMapStepPx);
    predicted = PredictProjectionError(*fit.sensor, fit, field, distances);
    for (const PredictedError& map : predicted) {
      const bool infinite = map.distance_mm >= kInfinityMm;
      char label[80];
      if (infinite) {
        std::snprintf(label, sizeof label, "infinity");
      } else {
        std::snprintf(label, sizeof label, "%.0f mm (n = %.2f)", map.distance_mm, map.distance_mm / rim_mm);
      }
      distance_labels.push_back(label);
      result["predicted_error"].push_back({{"distance_mm", infinite ? nlohmann::json("infinity") : nlohmann::json(map.distance_mm)},
                                           {"n_rim_radii", infinite ? nlohmann::json("infinity") : nlohmann::json(map.distance_mm / rim_mm)},
                                           {"median_px", map.median_px},
                                           {"max_px", map.max_px},
                                           {"field_pixels", map.pixels.size()},
                                           {"unpredicted_pixels", map.unpredicted}});
      if (!std::isfinite(map.max_px))
        warnings.push_back(std::string("the projection error at ") + label + " could not be predicted (no field pixel projects)");
      if (map.max_px > options.max_predicted_error_px) {
        // What would help: the valleys the data leave open (README "When the predicted
        // error warning fires").
        std::vector<std::string> help;
        if (farthest_mm < kOneDistanceRatio * nearest_mm) help.push_back("boards at other distances");
        const bool distortion_free = std::any_of(fit.parameters.begin(), fit.parameters.end(), [](const ParameterEstimate& p) {
          return (p.name == "k1" || p.name == "k2") && !p.fixed;
        });
        if (distortion_free) help.push_back("the distortion held (--fix distortion)");
        if (fit_options.tolerances.empty()) help.push_back("design tolerances (--tolerance)");
        help.push_back("more views over the whole field");
        std::string joined;
        for (size_t k = 0; k < help.size(); ++k) joined += (k ? (k + 1 == help.size() ? " or " : ", ") : "") + help[k];
        char text[400];
        std::snprintf(text, sizeof text,
                      "predicted projection error up to %.2f px (median %.2f) at %s exceeds %.2f px: the calibration "
                      "may misplace objects there by that much; %s would help",
                      map.max_px, map.median_px, label, options.max_predicted_error_px, joined.c_str());
        warnings.push_back(text);
      }
    }
    result["predicted_error_definition"] =
        "per pixel of the observed field: sqrt(trace(J C J^T)), the RMS length of the 2-D error vector of a point at "
        "that distance from its reflection point, C the fit's covariance (poses marginalised)";
  }
  result["warnings"] = warnings;
  for (size_t v = 0; v < usable.images.size(); ++v) result["per_view_rms_px"][usable.images[v].image] = fit.per_view_rms_px[v];
  for (const ParameterEstimate& p : fit.parameters)
    result["parameters"][p.name] = {{"value", p.value},
                                    {"std", std::isfinite(p.std) ? nlohmann::json(p.std) : nlohmann::json(nullptr)},
                                    {"fixed", p.fixed}};
  for (size_t v = 0; v < usable.images.size(); ++v) {
    if (!fit.view_left_out[v].empty()) continue;
    const TargetPose& pose = fit.poses[v];
    const Eigen::Quaterniond& q = pose.camera_from_target_rotation;
    result["poses"][usable.images[v].image] = {
        {"camera_from_target_quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}},
        {"camera_from_target_translation_mm",
         {pose.camera_from_target_translation_mm.x(), pose.camera_from_target_translation_mm.y(),
          pose.camera_from_target_translation_mm.z()}}};
  }

  const std::filesystem::path dir(options.out_dir);
  CreateOutputDirectory(dir);
  SaveSensorYaml(*fit.sensor, (dir / "sensor.yaml").string());
  if (!options.images.empty()) WriteDetections(detections, (dir / "detections.json").string());
  WriteFileAtomically((dir / "calibration.json").string(), [&](std::ostream& out) { out << result.dump(2) << '\n'; });
  WriteReport(dir / "report", usable, fit);
  for (size_t k = 0; k < predicted.size(); ++k)
    WritePredictedErrorMap((dir / "report" / ("predicted_error_" + std::to_string(k) + ".png")).string(), *fit.sensor,
                           predicted[k], kMapStepPx, options.max_predicted_error_px, distance_labels[k]);
  for (const std::string& w : warnings) std::fprintf(stderr, "omnical: warning: %s\n", w.c_str());
  if (!context.quiet) {
    std::printf("%zu views, %d corners: RMS %.4f px, %s; -> %s\n", usable.images.size(), observations, fit.rms_px,
                fit.converged ? "converged" : "NOT converged", options.out_dir.c_str());
    for (const ParameterEstimate& p : fit.parameters) {
      if (p.fixed) {
        std::printf("  %-16s %14.8g (fixed)\n", p.name.c_str(), p.value);
      } else {
        std::printf("  %-16s %14.8g +- %.3g\n", p.name.c_str(), p.value, p.std);
      }
    }
  }
}

}  // namespace

Command CalibrateCommand() {
  return {"calibrate", "Bundle fit of the non-central model from images or detections (and a guess, or the rim circle)",
          [](CLI::App& sub, const Context& context) -> CommandAction {
            auto options = std::make_shared<Options>();
            sub.add_option("--target", options->target_path, "Target spec (YAML, Kalibr keys)")->required();
            sub.add_option("--images", options->images,
                           "Directory of images or a glob pattern: detect here (detections.json is written to --out)");
            sub.add_option("--detections", options->detections_path, "Detections (JSON, from omnical detect)");
            sub.add_option("--sensor", options->sensor_path,
                           "Sensor guess (YAML): nominal design values. Without it the fit starts from the mirror's "
                           "rim circle in the images (orthographic lens, scale held)");
            sub.add_option("--profile", options->profile,
                           "Mirror family to fit: sphere, paraboloid, polynomial (default without a guess), hyperboloid "
                           "(needs --sensor); a guess of another family is converted")
                ->check(CLI::IsMember({"sphere", "paraboloid", "polynomial", "hyperboloid"}));
            sub.add_option("--rim-field-deg", options->rim_field_deg,
                           "Without a guess: the rim ray's angle from the mirror axis (Omega, deg) to start from")
                ->check(CLI::Range(10.0, 170.0))->capture_default_str();
            options->threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
            sub.add_option("--threads", options->threads, "Detection threads")->check(CLI::Range(1, 256))->capture_default_str();
            sub.add_option("--out", options->out_dir, "Output directory")->required();
            sub.add_option("--fix", options->fix, "Blocks held constant: lens, lens_scale, distortion, m, tilt, decenter, shape, poses");
            sub.add_option("--loss-px", options->loss_px, "Huber loss scale, px (0: least squares)")
                ->check(CLI::Range(0.0, 1000.0))->capture_default_str();
            sub.add_option("--max-iterations", options->max_iterations, "Solver iterations per stage")
                ->check(CLI::Range(1, 100000))->capture_default_str();
            sub.add_option("--detection-passes", options->detection_passes,
                           "With --images and an aprilgrid: pass 2 re-detects the corners through the first fit's "
                           "sensor and fits again (1: a single pass)")
                ->check(CLI::Range(1, 5))->capture_default_str();
            sub.add_option("--tolerance", options->tolerance,
                           "Design tolerances (one std) as weak priors, name=value,...: e.g. m_mm=2,decenter_mm=1,"
                           "tilt_deg=1,principal_point_px=10,k1=0.05 (adds to / overrides the guess file's tolerances:)");
            sub.add_option("--distance-mm", options->distances_mm,
                           "Distances (mm from the reflection point) at which to predict the projection error "
                           "(repeatable; default: the boards' median distance and infinity)")
                ->check(kPositive);
            sub.add_option("--distance-n", options->distances_n, "The same in mirror rim radii (the seed paper's n)")
                ->check(kPositive);
            sub.add_option("--max-predicted-error-px", options->max_predicted_error_px,
                           "Warn when the predicted projection error anywhere in the observed field exceeds this")
                ->check(CLI::Range(0.0, 1000.0))->capture_default_str();
            sub.add_flag("--leave-one-out", options->leave_one_out,
                         "Also fit without each image in turn; calibration.json gets each parameter's spread");
            return [options, &context]() { Run(*options, context); };
          }};
}

}  // namespace omnical::cli
