// A checkerboard junction from every pixel around it: the squares within 1.25 squares of
// the junction, fitted whole to the omni image (calib/printed_patch_fit.h) from a pose by
// PnP on the corners found around it. For the junctions the edge profiles of
// calib/refine_corners.h cannot read: at the rim, where the squares beyond the junction are
// cut to a sliver (the profiles need both sides of each edge), the inner squares' edges
// and their neighbours' junctions still place it through the sensor.
#pragma once

#include <Eigen/Core>
#include <map>
#include <opencv2/core.hpp>

#include "calib/board_warp.h"
#include "calib/target.h"
#include "model/sensor.h"

namespace omnical {

// Junction `id` of a checkerboard bent by `warp` from `start_px` (a detection or a
// prediction) in the omni image `grey` (8-bit), with `found_px` the image's other corners
// (id -> px; those within two squares on the board start the pose, all of them where those
// are under 4 or on a line). False when it cannot: no corner found around it, the junction
// off the mirror, the fit refused
// (calib/printed_patch_fit.h: over the squares or the junction's own half squares), or the
// junction moved over a quarter square.
bool FitCheckerJunction(const CalibrationTarget& target, const cv::Mat& grey, const Sensor& sensor, const BoardWarp& warp,
                        int id, const Eigen::Vector2d& start_px, const std::map<int, Eigen::Vector2d>& found_px,
                        Eigen::Vector2d* junction_px);

}  // namespace omnical
