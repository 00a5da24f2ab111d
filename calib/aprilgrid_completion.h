// AprilGrid tags the decoder cannot read, placed from those it can. Small, blurred, JPEG
// tags (a far board's: ~1.3 px per bit) still show their black squares, but not their bits:
// AprilTag reads none of them. The decoded tags of a view are mapped into a virtual
// perspective view aimed at them, and the unread tags are placed outwards from them a ring
// at a time (a tag next to a known one on the board's grid): each predicted through the
// homography of the 6 known tags nearest to it on the board (local: the view is a true
// perspective image only as far as the guess is right, so a board-wide homography drifts
// by pixels towards the rim), kept only where its black square is there: its border ring
// darker than the white gap around it by at least half the decoded tags' median contrast.
// A kept tag is known for the next ring. The predicted corners are then refined like any
// others (calib/refine_corners.h, in patches through the guess), which marks the ones it
// cannot settle `unrefined` (left out of the fit).
#pragma once

#include <opencv2/core.hpp>

#include "calib/detections.h"
#include "calib/target.h"
#include "model/sensor.h"

namespace omnical {

// `found` with the predicted tags added (4 corners each); `found` as it is for another
// target type or family (tag36h11 only: the test reads its black square), fewer than 4
// decoded tags, or when no view can be aimed at them.
ImageDetections CompleteAprilGrid(const CalibrationTarget& target, const cv::Mat& grey, const Sensor& guess,
                                  const ImageDetections& found);

}  // namespace omnical
