// An aprilgrid tag's four corners from every pixel around it: the printed pattern (black
// square, data bits, white gap, as the target spec prints it), blurred, is fitted to the omni
// image. Where the edge profiles of calib/refine_corners.h cannot settle a corner (near the
// rim a tag is squashed to a few px radially, and the profiles across its edges scatter by
// a tenth of a cell and more) the whole tag still holds hundreds of edge pixels.
//
// Model of a pixel p: paper + (ink - paper) x coverage(p), coverage the ink fraction of
// the board around the point where p's ray (the sensor's own, non-central) meets the tag's
// plane, under a Gaussian in the omni image (the optics' blur, sigma_px, and the pixel's
// width) carried to the board: part of it by 3 x 3 quadrature nodes through the second-
// order map pixel -> board (near the rim that map shears and bends over the blur's width;
// one Gaussian per board axis put a noise-free rim render's corners 0.36 px off, the
// quadrature 0.12), the rest as one Gaussian per board axis around each node, so the
// ink's rectangles blur separably (erf products). Fitted (Ceres, automatic derivatives,
// one Cauchy-weighted residual per pixel): the tag plane's pose (6), sigma_px, ink and
// paper levels, over the pixels within one cell of the tag's black square (data bits and
// gap included), from a pose by PnP on the given corners. The corners are the fitted
// pose's, projected through the sensor; a sensor error moves them only by how much it
// bends the image over one tag.
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>

#include "calib/target.h"
#include "model/sensor.h"

namespace omnical {

struct TagTemplateFit {
  std::array<Eigen::Vector2d, 4> corners_px;  // corner ids 4 tag + k, k = 0..3 (calib/target.h)
  double blur_px = 0.0;                       // the fitted Gaussian's sigma, omni px
  double contrast = 0.0;                      // paper - ink, grey levels
  double rms_grey = 0.0;                      // the fit's residual RMS, grey levels
  int pixels = 0;                             // fitted pixels
};

// Fits the tag with id `tag` (its corners' ids 4 tag + k) of an aprilgrid (tag36h11: a black square of 8
// cells with a white ring around, target.Reflectance) from `start_px`, its corners in the
// omni image `grey` (8-bit). False when it cannot: too few pixels on the mirror, the fit
// does not converge, no contrast, the pattern does not match (residual over a quarter of
// the contrast), an implausible blur, or a corner moved more than half a cell.
bool FitTagTemplate(const CalibrationTarget& target, const cv::Mat& grey, const Sensor& sensor, int tag,
                    const std::array<Eigen::Vector2d, 4>& start_px, TagTemplateFit* fit);

}  // namespace omnical
