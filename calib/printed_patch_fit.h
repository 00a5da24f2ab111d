// A piece of the printed target fitted whole to the omni image, pixel by pixel: where the
// edge profiles of calib/refine_corners.h cannot settle a corner (near the rim a tag or a
// square is squashed to a few px radially, and profiles across its edges scatter by a tenth
// of a cell and more; a junction the rim cuts on one side has no profiles there) the piece
// still holds hundreds of edge pixels.
//
// Model of a pixel p: paper + (ink - paper) x coverage(p), coverage the ink fraction of
// the board around the point where p's ray (the sensor's own, non-central) meets the
// piece's plane, under a Gaussian in the omni image (the optics' blur, sigma_px, and the
// pixel's width) carried to the board: part of it by 3 x 3 quadrature nodes through the
// second-order map pixel -> board (near the rim that map shears and bends over the blur's
// width; one Gaussian per board axis put a noise-free rim render's tag corners 0.36 px off,
// the quadrature 0.12), the rest as one Gaussian per board axis around each node, so the
// ink's rectangles (CalibrationTarget::InkRectangles) blur separably (erf products).
// Fitted (Ceres, automatic derivatives, one Cauchy-weighted residual per pixel): the
// board's pose (6), sigma_px, ink and paper levels; the board's warp, where it has one, is
// held (taken flat, a patch of 2.5 squares of the realistic renders' board, bent 3 mm, put
// mid-field junctions 0.047 px off the truth; bent, 0.009). Points of the piece are then
// the fitted pose's, projected through the sensor: a sensor error moves them only by how
// much it bends the image over the piece.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "calib/board_warp.h"
#include "calib/bundle_fit.h"
#include "calib/target.h"
#include "model/sensor.h"

namespace omnical {

// Which pixels are fitted: those in the omni image box whose ray meets the start pose's
// plane within the board box (target mm), and which lie kRimClearancePx and more from
// any pixel whose ray misses the mirror.
struct PatchRegion {
  Eigen::Vector2d board_low_mm, board_high_mm;
  Eigen::Vector2d image_low_px, image_high_px;
  // Pixels that must be clear of the rim that way, else no fit (a tag the rim cuts put its
  // corners 0.3 px off on a noise-free render).
  std::vector<Eigen::Vector2d> clear_px;
  // Pixels that must at least see the mirror (their ray meets it), else no fit.
  std::vector<Eigen::Vector2d> on_mirror_px;
  // The rim modelled instead of kept clear of: within the blur's reach of it, the board's
  // grey gives way to a fitted level beyond it, at the sensor's rim shifted by a fitted
  // amount (omni px; the sensor's rim may sit a px off the image's). For pieces the rim
  // cuts, whose edges run into it.
  bool model_rim = false;
  // Where the fitted points lie (target mm; none when high <= low): the fitted pixels there
  // (20 and more) must match on their own, residual RMS within a quarter of the contrast
  // (a finger over a junction is a small share of the squares around it).
  Eigen::Vector2d core_low_mm = Eigen::Vector2d::Zero(), core_high_mm = Eigen::Vector2d::Zero();
};

// Pixels within this distance of one whose ray misses the mirror (the rim, the camera
// body's reflection) mix the board with the dark beyond in their blur and box: not fitted.
constexpr int kRimClearancePx = 3;

// Whether every pixel within margin_px of `pixel` (a square) is on the mirror. A fitted
// point near the rim is kept only that far inside it: nearer, the rim's blur and a px of
// the sensor's rim error make it moot.
bool OnMirrorWithMargin(const Sensor& sensor, const Eigen::Vector2d& pixel, int margin_px);

// A pixel's signed distance inside the sensor's rim, omni px (negative beyond it): how far
// its reflection point's radius falls short of the rim's, over that radius's gradient
// across the image. The rays come from `wider`, SensorWithWiderRim(sensor, 1.15) (as the
// fits' pixels'); NaN where the rays around the pixel miss even that mirror.
double InsideRimPx(const Sensor& sensor, const Sensor& wider, const Eigen::Vector2d& pixel);

struct PatchFit {
  TargetPose pose;         // the fitted plane's camera_from_target
  double blur_px = 0.0;    // the fitted Gaussian's sigma, omni px
  double contrast = 0.0;   // paper - ink, grey levels
  double rms_grey = 0.0;   // the fit's residual RMS (plain, no loss), grey levels
  int pixels = 0;          // fitted pixels
  // With the rim modelled: how far beyond the sensor's rim the image's lies here, omni px
  // (a pixel is InsideRimPx + rim_shift_px inside the fitted rim); 0 where no fitted pixel
  // came near enough the rim to say (the shift then held), and where the shift ended on its
  // outer bound (not measured, only pushed there: the sensor's rim is then the safer one).
  double rim_shift_px = 0.0;
};

// Fits the target's ink, on the board bent by `warp` (calib/board_warp.h), over `region` of
// the omni image `grey` (8-bit) from `start` (the board's pose: only its plane near the
// region matters). False when it cannot: too few pixels on the mirror (60; 30 two px and
// more inside the rim), the fit not usable, no contrast (20 grey levels), an implausible
// blur (0.1-4 px), or a residual over a quarter of the contrast (the pattern does not
// match), over the whole region or over its core.
bool FitPrintedPatch(const CalibrationTarget& target, const cv::Mat& grey, const Sensor& sensor, const BoardWarp& warp,
                     const TargetPose& start, const PatchRegion& region, PatchFit* fit);

}  // namespace omnical
