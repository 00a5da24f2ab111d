// The mirror's rim in an omni image: the circle where the bright mirror disc ends and the
// dark housing (or the unlit sensor) begins. Without a datasheet or a guess it is all an
// image tells about the sensor: its centre is the principal point (to the mirror's
// decenter and tilt) and its radius the scale of the image mapping.
//
// Along 720 rays from a centre, the rim is the radius with the largest drop from the mean
// intensity just inside to the mean over a long stretch outside (the outside of the rim
// stays dark everywhere, the outside of an edge inside the mirror does not); a circle is
// fitted to those points by RANSAC (1.5 px) and least squares, then the search repeats
// around it. Rays that leave the image before the rim (a disc cut by the frame) drop out.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <optional>
#include <string>
#include <vector>

#include "model/sensor.h"

namespace omnical {

struct RimCircle {
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
  double radius_px = 0.0;
  double inlier_fraction = 0.0;  // of the 720 rays, how many agree with the circle (1.5 px)
  double rms_px = 0.0;           // of the inliers about the fitted circle
};

// Nothing if no circle is supported by at least a third of the rays.
std::optional<RimCircle> DetectRimCircle(const cv::Mat& grey);

// The median centre and radius of several images' circles (the rim does not move on the
// sensor); nothing if none was found.
std::optional<RimCircle> MedianRimCircle(const std::vector<RimCircle>& circles);

// The sensor with its rim radius where the images show it: the median mirror radius (mm)
// of the reflection points seen along the circle. A fit places the mirror from the corners
// it sees and takes the rim from the design (or, wider, from the farthest corner); near the
// rim that put a realistic render's first fit's rim 7-12 px beyond the image's, and the
// tags the rim cuts, fitted across a rim that was not there, were refused. Nothing when
// under half the circle lies in the image (clear of the camera's reflection), or the
// radius would shrink by over 10 % or grow by over 10 %: a circle that is not this mirror's
// rim; then `why` (if given) says which, in one line. `rim_from_corners`: the sensor's rim
// is only its farthest corner's (a fit without a design, whose boards may not reach the
// rim); then a mirror without free-form terms may grow by up to 25 %, its curvature
// continuing past the corners as a conic mirror's does.
std::optional<Sensor> SensorWithImageRim(const Sensor& sensor, const RimCircle& rim, std::string* why = nullptr,
                                         bool rim_from_corners = false);

}  // namespace omnical
