#include "calib/detect.h"

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagStandard41h12.h>

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <map>
#include <stdexcept>

namespace omnical {

ImageDetections DetectAprilGrid(const CalibrationTarget& target, const cv::Mat& grey, DetectionStats* stats) {
  if (target.type() != CalibrationTarget::Type::kAprilGrid)
    throw std::invalid_argument("only aprilgrid targets can be detected so far");
  DetectionStats local;
  cv::Mat flipped;
  cv::flip(grey, flipped, 1);  // undo the mirror's reversal of handedness
  if (!flipped.isContinuous()) flipped = flipped.clone();
  apriltag_family_t* family = target.family() == "tag36h11" ? tag36h11_create() : tagStandard41h12_create();
  apriltag_detector_t* detector = apriltag_detector_create();
  apriltag_detector_add_family(detector, family);
  detector->quad_decimate = 1.0f;  // full resolution: corners are what calibration needs
  detector->nthreads = 1;          // images are processed in parallel instead
  detector->refine_edges = true;
  image_u8_t frame{flipped.cols, flipped.rows, static_cast<int32_t>(flipped.step), flipped.data};
  zarray_t* detections = apriltag_detector_detect(detector, &frame);
  const int first = target.code_offset(), last = first + target.cols() * target.rows() - 1;
  std::map<int, std::array<Eigen::Vector2d, 4>> by_id;
  std::map<int, int> seen;
  for (int i = 0; i < zarray_size(detections); ++i) {
    apriltag_detection_t* d;
    zarray_get(detections, i, &d);
    if (d->id < first || d->id > last) {
      ++local.wrong_ids;
      continue;
    }
    if (++seen[d->id] > 1) continue;
    std::array<Eigen::Vector2d, 4> corners;
    for (int k = 0; k < 4; ++k) {
      // AprilTag puts pixel centres at +0.5; flip the column back.
      const double u_flipped = d->p[k][0] - 0.5, v = d->p[k][1] - 0.5;
      corners[k] = Eigen::Vector2d(grey.cols - 1 - u_flipped, v);
    }
    by_id[d->id] = corners;
  }
  apriltag_detections_destroy(detections);
  apriltag_detector_destroy(detector);
  if (target.family() == "tag36h11") tag36h11_destroy(family); else tagStandard41h12_destroy(family);

  ImageDetections image;
  for (const auto& [id, corners] : by_id) {
    if (seen[id] > 1) {
      ++local.duplicates;
      continue;
    }
    ++local.tags;
    for (int k = 0; k < 4; ++k) image.corners.push_back({4 * id + k, corners[k]});
  }
  if (stats) *stats = local;
  return image;
}

ImageDetections DetectCheckerboard(const CalibrationTarget& target, const cv::Mat& grey) {
  if (target.type() != CalibrationTarget::Type::kCheckerboard)
    throw std::invalid_argument("not a checkerboard target");
  cv::Mat flipped;
  cv::flip(grey, flipped, 1);  // undo the mirror's reversal of handedness
  std::vector<cv::Point2f> corners;
  ImageDetections image;
  if (!cv::findChessboardCornersSB(flipped, cv::Size(target.cols(), target.rows()), corners,
                                   cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_ACCURACY))
    return image;
  for (int i = 0; i < static_cast<int>(corners.size()); ++i) {
    const int row_down = i / target.cols(), col = i % target.cols();
    const int id = (target.rows() - 1 - row_down) * target.cols() + col;  // rows counted upwards
    image.corners.push_back({id, Eigen::Vector2d(grey.cols - 1 - corners[i].x, corners[i].y)});
  }
  std::sort(image.corners.begin(), image.corners.end(),
            [](const CornerObservation& a, const CornerObservation& b) { return a.id < b.id; });
  return image;
}

ImageDetections DetectTarget(const CalibrationTarget& target, const cv::Mat& grey) {
  return target.type() == CalibrationTarget::Type::kAprilGrid ? DetectAprilGrid(target, grey)
                                                               : DetectCheckerboard(target, grey);
}

}  // namespace omnical
