#include "calib/calibration_summary.h"

#include <cmath>
#include <cstdarg>
#include <cstdio>

namespace omnical {
namespace {

// printf into a std::string: the summary keeps the CLI's fixed-width columns.
void AppendFormatted(std::string& out, const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list copy;
  va_copy(copy, args);
  const int size = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  if (size > 0) {
    std::string line(static_cast<size_t>(size) + 1, '\0');
    std::vsnprintf(line.data(), line.size(), format, args);
    line.pop_back();
    out += line;
  }
  va_end(args);
}

// "<what> chosen by 5 held-out folds (N corners): a: x px (chosen) b: y px".
void AppendNamedChoice(const char* what, const NamedChoice& choice, std::string* out) {
  *out += std::string(what) + " chosen by " + std::to_string(choice.folds) + " held-out folds (" +
          std::to_string(choice.held_out_corners) + " corners):";
  for (size_t k = 0; k < choice.candidates.size(); ++k) {
    const char* chosen = choice.candidates[k] == choice.chosen ? " (chosen)" : "";
    if (std::isfinite(choice.held_out_rms_px[k]))
      AppendFormatted(*out, " %s: %.4f px%s", choice.candidates[k].c_str(), choice.held_out_rms_px[k], chosen);
    else  // calibration.json's null: a fold without a fit, a valid sensor or a held-out residual
      AppendFormatted(*out, " %s: not scored%s", choice.candidates[k].c_str(), chosen);
  }
  *out += choice.AnyScored() ? "\n" : " (none scored: the first kept)\n";
}

// The knot counts as names ("4", "8"; the mirror family for no spline), to print as the
// other choices print.
NamedChoice NamedKnotChoice(const KnotChoice& knots) {
  NamedChoice named;
  for (int count : knots.candidates) {
    named.candidates.push_back(count > 0 ? std::to_string(count) : knots.base_profile);
    if (count == knots.chosen) named.chosen = named.candidates.back();
  }
  named.held_out_rms_px = knots.held_out_rms_px;
  named.held_out_corners = knots.held_out_corners;
  named.folds = knots.folds;
  return named;
}

}  // namespace

std::string CalibrationSummaryText(const CalibrationResult& result, const std::string& destination) {
  const CalibrationRecord& record = result.record;
  std::string out;
  if (const auto& rim = record.rim_circle)
    AppendFormatted(out, "rim circle: centre (%.2f, %.2f) px, radius %.2f px (%.0f%% of rays, %.2f px RMS)\n",
                    rim->centre_px.x(), rim->centre_px.y(), rim->radius_px, 100.0 * rim->inlier_fraction, rim->rms_px);
  int corners = 0;
  for (const ImageDetections& image : result.views.images) corners += static_cast<int>(image.corners.size());
  AppendFormatted(out, "%zu views, %d corners: RMS %.4f px, %s", result.views.images.size(), corners, record.rms_px,
                  record.converged ? "converged" : "NOT converged");
  out += destination.empty() ? "\n" : "; -> " + destination + "\n";
  for (const ParameterEstimate& p : record.parameters) {
    if (p.fixed) {
      AppendFormatted(out, "  %-16s %14.8g (fixed)\n", p.name.c_str(), p.value);
    } else {
      if (std::isfinite(p.std))
        AppendFormatted(out, "  %-16s %14.8g +- %.3g\n", p.name.c_str(), p.value, p.std);
      else
        AppendFormatted(out, "  %-16s %14.8g (std not determined)\n", p.name.c_str(), p.value);
    }
  }
  AppendFormatted(out, "all fitted corners, outliers included: RMS %.4f px\n", record.rms_all_px);
  if (const auto& warp = record.board_warp)
    AppendFormatted(out, "board warp: %.3f +- %.3f mm along x, %.3f +- %.3f mm along y (deflection at the centre)\n",
                    warp->warp.x_mm, warp->std_x_mm, warp->warp.y_mm, warp->std_y_mm);
  if (const auto& warp = record.board_warp; warp && !warp->warp.relief_mm.empty()) {
    double square = 0.0, largest = 0.0;
    for (const auto& entry : warp->warp.relief_mm) {
      square += entry.second * entry.second;
      largest = std::max(largest, std::abs(entry.second));
    }
    AppendFormatted(
        out,
        "board relief (each corner's own offset on top of the warp): RMS %.3f mm, largest %.3f mm over %zu corners\n",
        std::sqrt(square / warp->warp.relief_mm.size()), largest, warp->warp.relief_mm.size());
  }
  for (const CalibrationRecord::PredictedErrorSummary& p : record.predicted_error) {
    if (std::isfinite(p.n_rim_radii)) {
      AppendFormatted(out, "predicted projection error at %.0f mm (n = %.2f): ", p.distance_mm, p.n_rim_radii);
    } else {
      out += "predicted projection error at infinity: ";
    }
    AppendFormatted(out, "median %.3f px, worst %.3f px (", p.median_px, p.max_px);
    if (std::isfinite(p.aligned_at_mm)) {
      AppendFormatted(out, "after the rigid alignment fitted at %.0f mm, the boards' median distance", p.aligned_at_mm);
    } else {
      out += "after the best rigid alignment";
    }
    AppendFormatted(out, "; in the camera's frame worst %.3f px)\n", p.in_camera_frame_max_px);
  }
  if (const auto& knots = record.knot_choice) AppendNamedChoice("knots", NamedKnotChoice(*knots), &out);
  if (const auto& lens = record.lens_choice) AppendNamedChoice("lens", *lens, &out);
  if (const auto& profile = record.profile_choice) AppendNamedChoice("mirror family", *profile, &out);
  if (const auto& tangential = record.tangential_choice) AppendNamedChoice("tangential terms p1, p2", *tangential, &out);
  if (const auto& relief = record.relief_choice) AppendNamedChoice("board shape", *relief, &out);
  if (const auto& held = record.holdout)
    AppendFormatted(out, "held out: %zu views, %d corners: RMS %.4f px (training %.4f px, ratio %.2f)\n",
                    held->images.size(), held->corners, held->rms_px, record.rms_all_px, held->rms_px / record.rms_all_px);
  if (const auto& folds = record.holdout_folds)
    AppendFormatted(out,
                    "every view held out once (%zu folds of %d): %d corners, RMS %.4f px (training %.4f px, ratio "
                    "%.2f)\n",
                    folds->folds.size(), folds->views_per_fold, folds->corners, folds->rms_px, folds->training_rms_px,
                    folds->rms_px / folds->training_rms_px);
  if (const auto& cross = record.cross_validation)
    AppendFormatted(out,
                    "two halves (RMS %.4f / %.4f px) differ at %.0f mm by %.4f px RMS, %.4f px max over %d field "
                    "pixels (%s: %.3f deg, %.2f mm)\n",
                    cross->half_rms_px[0], cross->half_rms_px[1], cross->diff.distance_mm, cross->diff.rms_px,
                    cross->diff.max_px, cross->diff.compared,
                    cross->diff.aligned ? "after the best rigid alignment there" : "alignment FAILED, unaligned",
                    cross->diff.rotation_deg,
                    cross->diff.translation_mm.norm());
  if (const auto& cross = record.cross_validation; cross && cross->diff_aligned_at_boards &&
                                                     cross->diff_aligned_at_boards->aligned) {
    const ProjectionDiff& once = *cross->diff_aligned_at_boards;
    AppendFormatted(out,
                    "  with one rigid alignment fitted at the boards' %.0f mm (as the predicted error): %.4f px RMS, "
                    "%.4f px max over %d field pixels\n",
                    once.aligned_at_mm, once.rms_px, once.max_px, once.compared);
  }
  return out;
}

}  // namespace omnical
