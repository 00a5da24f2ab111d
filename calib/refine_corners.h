// Sub-pixel refinement of detected corners. Detectors place corners from fitted quad
// edges (AprilTag) or a smoothed response (checkerboard); the gradient-orthogonality
// criterion (OpenCV's cornerSubPix) is sharper when its window holds just the corner's two
// edges. The window is sized per corner from the target itself: a fraction of the tag's
// border cell (an aprilgrid corner is the corner of the tag's black square, so the window
// must stay inside one cell) or of the checkerboard square.
//
// With a sensor guess, each corner is refined in a small perspective patch resampled from
// the omni image (bicubic) around the corner's own ray, magnified ~2x: the mirror's
// anisotropic compression near the rim is undone there, and the refined point is mapped
// back through the patch's own table of exact projections, so the guess's error does not
// move it. Without a guess the refinement runs on the omni image; corners too small for
// it keep the detector's position.
//
// Through a guess, an aprilgrid tag whose four corners were found is then fitted whole
// (calib/tag_template_fit.h: its printed pattern, blurred, against every pixel around it,
// along the guess's own rays) and takes those corners, also where the edge profiles
// failed; a fit whose residual is over 2.5 x the image's median (relative to contrast)
// settled in another minimum and is not used. On the realistic aprilgrid renders through
// the true sensor the edge profiles were 0.25 px (mid-field) and 0.32 px (at the rim) from
// the truth, the tag fits 0.033 and 0.109 (TagTemplateFit.PutsTagCornersOnTheTruth...).
// A tag with predicted corners (calib/checkerboard_completion.h), or found whole with a
// corner at the rim, is fitted across the rim, and keeps the corners the mirror shows.
// Through a guess, a checkerboard junction whose edges cannot be read (kEdges, or any
// prediction) is fitted whole (calib/checker_junction_fit.h): at the rim, where the squares
// beyond it are a sliver, 0.03-0.10 px from the truth on the realistic renders.
//
// Measured (tests/bench/detection_recall, docs/detection-recall.md): aprilgrid corners
// 0.079-0.127 px RMS from virtual views -> 0.045-0.092 px refined in patches; raw
// 0.19-0.40 -> 0.11-0.35 refined on the omni image. Checkerboards on renders 0.189 ->
// 0.068 px. On the real Mei images (grid steps 8-36 px) refining every corner by
// cornerSubPix made the fit's halves differ more (0.317 -> 0.347 px at 2 m); refining only
// corners whose grid step in the omni image is kMinRefinedCheckerStepPx or more improved
// every figure (`calibrate --board-warp`: all-corner RMS 0.352 -> 0.326 px, halves 0.317 ->
// 0.267 px, held-out views' RMS 1.30 -> 1.15 x the training views'; docs/calibrate.md):
// detect's default, and calibrate's `--checkerboard-subpixel`. calibrate refines every
// checkerboard corner by its edges (kEdges) through its first fit: on the real images
// all-corner RMS 0.326 -> 0.285 px and every view held out in turn 0.345 -> 0.310 px; on
// the realistic renders' 6 re-rendered seeds no inward bias (CalibrationOptions::
// checkerboard_edges).
#pragma once

#include <opencv2/core.hpp>

#include "calib/board_warp.h"
#include "calib/detections.h"
#include "calib/target.h"
#include "model/sensor.h"

namespace omnical {

struct CornerRefinementStats {
  int refined = 0;  // moved by the refinement
  int kept = 0;     // left where the detector put them (window too small, no neighbours, or diverged)
  // Aprilgrid corners whose refinement through a guess failed (occluded, cut by the rim, a
  // neighbour missing) keep the detector's position marked `unrefined`: it is ~5x worse
  // (0.1-9 px on renders) and, unweighted among refined ones, biased the fit's mirror size.
  int unrefined = 0;
};

// A checkerboard's cornerSubPix window on a grid step under this (omni px) holds too few
// pixels: on the real Mei images it moved corners that fitted at 0.2 px by 1.5-2 px
// (calib/checkerboard_candidates.cc judges corners by it from the same step on).
constexpr double kMinRefinedCheckerStepPx = 20.0;

// How checkerboard corners are refined in patches through a guess. kSubPixel: cornerSubPix
// on the junction (grid steps of min_checker_step_px and more). kEdges: every corner, its
// two edges located along profiles across them on both sides of the junction (mid-level
// crossings, unbiased for a blur symmetric across an edge) from 0.25 to 0.85 of a square,
// each fitted by a parabola (a bent board's edge, or one through an imperfect guess, is a
// curve: a line would cut its chord, off the corner), the tangents at the corner
// intersected. cornerSubPix's gradient window is biased where the blur varies across it:
// in a patch resampled from near the rim the omni image's blur is stretched more on the
// outer side, and OpenCV's own corners (kept on small squares) sat 0.02-0.11 px inwards
// per view on the realistic checkerboard renders, enough to put fx 11 std off on a
// re-rendered set (docs/calibrate.md, "Checkerboard corners by their edges").
enum class CheckerRefinement { kSubPixel, kEdges };

// Checkerboard corners whose nearest detected grid neighbour lies closer than
// min_checker_step_px in the omni image keep the detector's position (counted as kept),
// except with kEdges through a guess.
// fit_whole_tags: the aprilgrid tags fitted whole through the guess (above); off, the edge
// profiles alone (a first pass whose corners only start a fit: a quarter of the time).
// warp: the board's bend, which the pieces fitted whole follow (calib/printed_patch_fit.h).
ImageDetections RefineCorners(const CalibrationTarget& target, const cv::Mat& grey, const Sensor* guess,
                              const ImageDetections& detections, CornerRefinementStats* stats = nullptr,
                              double min_checker_step_px = 0.0,
                              CheckerRefinement checker_refinement = CheckerRefinement::kSubPixel,
                              bool fit_whole_tags = true, const BoardWarp& warp = BoardWarp());

}  // namespace omnical
