#include "calib/calibration_json.h"

#include <nlohmann/json.hpp>

#include <cmath>

#include "calib/fit_covariance.h"
#include "calib/predicted_error.h"
#include "model/io/atomic_write.h"
#include "model/input_error.h"
#include "model/io/json_file.h"

namespace omnical {
namespace {

using nlohmann::json;

const char* const kPredictedErrorDefinition =
    "per pixel of the observed field: sqrt(trace(J C J^T)), the RMS length of the 2-D error vector of a point at "
    "that distance from its reflection point, C the fit's covariance (poses marginalised)";

json NumberOrNull(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }
double NumberOrNan(const json& value) { return value.is_null() ? NAN : value.get<double>(); }
json DistanceOrInfinity(double value, bool infinite) { return infinite ? json("infinity") : json(value); }
double ReadDistance(const json& value, double infinity) {
  return value.is_string() && value.get<std::string>() == "infinity" ? infinity : value.get<double>();
}

json ToJson(const CalibrationRecord& r) {
  json j;
  j["rms_px"] = r.rms_px;
  j["converged"] = r.converged;
  j["outliers"] = r.outliers;
  j["dropped"] = r.dropped;
  j["unrefined_corners_left_out"] = r.unrefined_corners_left_out;
  j["observations"] = r.observations;
  j["solver_report"] = r.solver_report;
  j["fixed_blocks"] = r.fixed_blocks;
  j["robust_loss_px"] = r.robust_loss_px;
  j["covariance_ok"] = r.covariance_ok;
  j["start"] = r.start;
  j["detection_passes"] = r.detection_passes;
  if (r.rim_circle)
    j["rim_circle"] = {{"centre_px", {r.rim_circle->centre_px.x(), r.rim_circle->centre_px.y()}},
                       {"radius_px", r.rim_circle->radius_px},
                       {"inlier_fraction", r.rim_circle->inlier_fraction},
                       {"rms_px", r.rim_circle->rms_px}};
  for (const auto& [name, s] : r.leave_one_out) j["leave_one_out"][name] = {{"min", s.min}, {"max", s.max}, {"std", s.std}};
  j["target_distance_mm"] = {{"nearest", r.nearest_target_mm}, {"farthest", r.farthest_target_mm}};
  for (const auto& [image, why] : r.views_left_out) j["views_left_out"][image] = why;
  j["outlier_threshold_px"] = r.outlier_threshold_px;
  for (const auto& [image, count] : r.per_view_outliers) j["per_view_outliers"][image] = count;
  j["sigma_px"] = r.sigma_px;
  j["tolerances"] = r.tolerances;
  j["rim_radius_mm"] = {{"guess", r.guess_rim_radius_mm}, {"fitted", r.fitted_rim_radius_mm}};
  if (r.covariance_ok) {
    j["covariance"]["names"] = r.covariance_names;
    for (int row = 0; row < r.covariance.rows(); ++row) {
      std::vector<double> values(r.covariance.cols());
      for (int col = 0; col < r.covariance.cols(); ++col) values[col] = r.covariance(row, col);
      j["covariance"]["matrix"].push_back(values);
    }
    // The same as correlations (unit diagonal), for people reading the file.
    const Eigen::MatrixXd correlation = CorrelationOf(r.covariance);
    j["correlation"]["names"] = r.covariance_names;
    for (int row = 0; row < correlation.rows(); ++row) {
      std::vector<double> values(correlation.cols());
      for (int col = 0; col < correlation.cols(); ++col) values[col] = correlation(row, col);
      j["correlation"]["matrix"].push_back(values);
    }
    if (std::isfinite(r.scale_block_condition)) j["scale_block_condition"] = r.scale_block_condition;
  }
  for (const auto& p : r.predicted_error) {
    const bool infinite = p.distance_mm >= kInfinityMm;
    j["predicted_error"].push_back({{"distance_mm", DistanceOrInfinity(p.distance_mm, infinite)},
                                    {"n_rim_radii", DistanceOrInfinity(p.n_rim_radii, infinite)},
                                    {"median_px", p.median_px},
                                    {"max_px", p.max_px},
                                    {"field_pixels", p.field_pixels},
                                    {"unpredicted_pixels", p.unpredicted_pixels}});
  }
  if (r.covariance_ok) j["predicted_error_definition"] = kPredictedErrorDefinition;
  j["warnings"] = r.warnings;
  for (const auto& [image, rms] : r.per_view_rms_px) j["per_view_rms_px"][image] = rms;
  for (const ParameterEstimate& p : r.parameters)
    j["parameters"][p.name] = {{"value", p.value}, {"std", NumberOrNull(p.std)}, {"fixed", p.fixed}};
  for (const auto& [image, pose] : r.poses) {
    const Eigen::Quaterniond& q = pose.camera_from_target_rotation;
    const Eigen::Vector3d& t = pose.camera_from_target_translation_mm;
    j["poses"][image] = {{"camera_from_target_quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}},
                         {"camera_from_target_translation_mm", {t.x(), t.y(), t.z()}}};
  }
  return j;
}

CalibrationRecord FromJson(const json& j, const std::string& name) {
  CalibrationRecord r;
  std::string field;
  // Each field is read under its name so a type error names it.
  auto at = [&](const char* key) -> const json& {
    field = key;
    return j.at(key);
  };
  try {
    if (!j.is_object()) throw InputError(InputMessage(name, "", "is not a JSON object"));
    r.rms_px = at("rms_px").get<double>();
    r.converged = at("converged").get<bool>();
    r.outliers = at("outliers").get<int>();
    r.dropped = at("dropped").get<int>();
    r.unrefined_corners_left_out = at("unrefined_corners_left_out").get<int>();
    r.observations = at("observations").get<int>();
    r.solver_report = at("solver_report").get<std::string>();
    r.fixed_blocks = at("fixed_blocks").get<std::set<std::string>>();
    r.robust_loss_px = at("robust_loss_px").get<double>();
    r.covariance_ok = at("covariance_ok").get<bool>();
    r.start = at("start").get<std::string>();
    r.detection_passes = at("detection_passes").get<int>();
    if (j.contains("rim_circle")) {
      const json& c = at("rim_circle");
      r.rim_circle = CalibrationRecord::RimCircleRecord{
          Eigen::Vector2d(c.at("centre_px").at(0).get<double>(), c.at("centre_px").at(1).get<double>()),
          c.at("radius_px").get<double>(), c.at("inlier_fraction").get<double>(), c.at("rms_px").get<double>()};
    }
    if (j.contains("leave_one_out"))
      for (const auto& [parameter, s] : at("leave_one_out").items())
        r.leave_one_out[parameter] = {s.at("min").get<double>(), s.at("max").get<double>(), s.at("std").get<double>()};
    const json& distance = at("target_distance_mm");
    r.nearest_target_mm = distance.at("nearest").is_null() ? HUGE_VAL : distance.at("nearest").get<double>();
    r.farthest_target_mm = distance.at("farthest").get<double>();
    if (j.contains("views_left_out")) r.views_left_out = at("views_left_out").get<std::map<std::string, std::string>>();
    r.outlier_threshold_px = at("outlier_threshold_px").get<double>();
    if (j.contains("per_view_outliers")) r.per_view_outliers = at("per_view_outliers").get<std::map<std::string, int>>();
    r.sigma_px = at("sigma_px").get<double>();
    if (!at("tolerances").is_null()) r.tolerances = at("tolerances").get<DesignTolerances>();
    r.guess_rim_radius_mm = at("rim_radius_mm").at("guess").get<double>();
    r.fitted_rim_radius_mm = j.at("rim_radius_mm").at("fitted").get<double>();
    if (j.contains("covariance")) {
      const json& c = at("covariance");
      r.covariance_names = c.at("names").get<std::vector<std::string>>();
      const int size = static_cast<int>(r.covariance_names.size());
      r.covariance.resize(size, size);
      for (int row = 0; row < size; ++row)
        for (int col = 0; col < size; ++col) r.covariance(row, col) = c.at("matrix").at(row).at(col).get<double>();
    }
    if (j.contains("scale_block_condition")) r.scale_block_condition = at("scale_block_condition").get<double>();
    if (j.contains("predicted_error"))
      for (const json& p : at("predicted_error"))
        r.predicted_error.push_back({ReadDistance(p.at("distance_mm"), kInfinityMm), ReadDistance(p.at("n_rim_radii"), HUGE_VAL),
                                     NumberOrNan(p.at("median_px")), NumberOrNan(p.at("max_px")),
                                     p.at("field_pixels").get<int>(), p.at("unpredicted_pixels").get<int>()});
    r.warnings = at("warnings").get<std::vector<std::string>>();
    if (j.contains("per_view_rms_px"))  // a view left out has no RMS: null
      for (const auto& [image, rms] : at("per_view_rms_px").items()) r.per_view_rms_px[image] = NumberOrNan(rms);
    for (const auto& [parameter, p] : at("parameters").items())
      r.parameters.push_back({parameter, p.at("value").get<double>(), NumberOrNan(p.at("std")), p.at("fixed").get<bool>()});
    if (j.contains("poses"))
      for (const auto& [image, p] : at("poses").items()) {
        const json& q = p.at("camera_from_target_quaternion_wxyz");
        const json& t = p.at("camera_from_target_translation_mm");
        TargetPose pose;
        pose.camera_from_target_rotation =
            Eigen::Quaterniond(q.at(0).get<double>(), q.at(1).get<double>(), q.at(2).get<double>(), q.at(3).get<double>());
        pose.camera_from_target_translation_mm = Eigen::Vector3d(t.at(0).get<double>(), t.at(1).get<double>(), t.at(2).get<double>());
        r.poses[image] = pose;
      }
  } catch (const json::exception& error) {
    throw InputError(InputMessage(name, field, std::string("missing or of the wrong type (") + error.what() + ")"));
  }
  return r;
}

}  // namespace

std::string CalibrationJsonText(const CalibrationRecord& record) { return ToJson(record).dump(2) + "\n"; }

void WriteCalibrationJson(const CalibrationRecord& record, const std::string& path) {
  const std::string text = CalibrationJsonText(record);
  WriteFileAtomically(path, [&](std::ostream& out) { out << text; });
}

CalibrationRecord ParseCalibrationJson(const std::string& text, const std::string& name) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception&) {
    throw InputError(InputMessage(name, "", "is not valid JSON"));
  }
  return FromJson(j, name);
}

CalibrationRecord ReadCalibrationJson(const std::string& path) { return FromJson(ReadJsonFile(path), path); }

}  // namespace omnical
