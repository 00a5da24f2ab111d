#include "calib/detect.h"

#include "calib/bilinear.h"
#include "calib/virtual_view.h"

#include <Eigen/Geometry>
#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagStandard41h12.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>

namespace omnical {

namespace {

// AprilTag 3 over an image (corners in its pixel-centre coordinates): the target's ids
// only, and an id decoded twice dropped altogether (which copy is the tag is unknown).
std::map<int, std::array<Eigen::Vector2d, 4>> DetectTags(const CalibrationTarget& target, const cv::Mat& image,
                                                         DetectionStats* stats) {
  apriltag_family_t* family = target.family() == "tag36h11" ? tag36h11_create() : tagStandard41h12_create();
  apriltag_detector_t* detector = apriltag_detector_create();
  apriltag_detector_add_family(detector, family);
  detector->quad_decimate = 1.0f;  // full resolution: corners are what calibration needs
  detector->nthreads = 1;          // images are processed in parallel instead
  detector->refine_edges = true;
  cv::Mat continuous = image.isContinuous() ? image : image.clone();
  image_u8_t frame{continuous.cols, continuous.rows, static_cast<int32_t>(continuous.step), continuous.data};
  zarray_t* detections = apriltag_detector_detect(detector, &frame);
  const int first = target.code_offset(), last = first + target.cols() * target.rows() - 1;
  DetectionStats local;
  std::map<int, std::array<Eigen::Vector2d, 4>> tags;
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
    for (int k = 0; k < 4; ++k) corners[k] = Eigen::Vector2d(d->p[k][0] - 0.5, d->p[k][1] - 0.5);  // AprilTag's centres: +0.5
    tags[d->id] = corners;
  }
  for (const auto& [id, count] : seen)
    if (count > 1) tags.erase(id), ++local.duplicates;
  local.tags = static_cast<int>(tags.size());
  apriltag_detections_destroy(detections);
  apriltag_detector_destroy(detector);
  if (target.family() == "tag36h11") tag36h11_destroy(family); else tagStandard41h12_destroy(family);
  if (stats) *stats = local;
  return tags;
}

// Whether a checkerboard's ids, in order (id = row * cols + col, rows upwards), are the
// board's turned by 180 deg about its normal: the grid's corner set is the same either way.
// The board's bottom-left square is ink (calib/target.h). With cols + rows odd the turn
// swaps the colours of the squares at corner 0, so the print decides: the squares at
// corner 0 on its (-x, -y) / (+x, +y) diagonal are dark in the board's order. With cols +
// rows even the board is symmetric and the order is a convention: rows count up away from
// the image centre, which for a board held upright around a vertical mirror axis is up
// (larger Omega images farther out), so the poses of such boards come out upright.
bool CheckerboardTurnedAround(const CalibrationTarget& target, const cv::Mat& grey,
                              const std::vector<CornerObservation>& corners) {
  const int cols = target.cols(), rows = target.rows();
  if (static_cast<int>(corners.size()) != cols * rows || cols < 2 || rows < 2) return false;
  auto at = [&](int row, int col) { return corners[row * cols + col].pixel; };
  if ((cols + rows) % 2 == 1) {
    const Eigen::Vector2d origin = at(0, 0), along_x = at(0, 1) - origin, along_y = at(1, 0) - origin;
    auto square = [&](double sx, double sy) {  // mean of a few samples inside the square
      double sum = 0.0;
      int count = 0;
      for (double f : {0.3, 0.5}) {
        const Eigen::Vector2d p = origin + f * (sx * along_x + sy * along_y);
        const double value = Bilinear<uchar>(grey, p.x(), p.y());
        if (std::isfinite(value)) sum += value, ++count;
      }
      return count ? sum / count : NAN;
    };
    const double diagonal = square(-1, -1) + square(1, 1), other = square(1, -1) + square(-1, 1);
    if (std::isfinite(diagonal) && std::isfinite(other)) return diagonal > other;
  }
  Eigen::Vector2d centre = Eigen::Vector2d::Zero(), up = Eigen::Vector2d::Zero();
  for (const CornerObservation& c : corners) centre += c.pixel / corners.size();
  for (int col = 0; col < cols; ++col) up += at(rows - 1, col) - at(0, col);
  const Eigen::Vector2d image_centre(0.5 * (grey.cols - 1), 0.5 * (grey.rows - 1));
  return up.dot(centre - image_centre) < 0.0;
}

}  // namespace

ImageDetections DetectAprilGrid(const CalibrationTarget& target, const cv::Mat& grey, DetectionStats* stats,
                                bool mirrored) {
  if (target.type() != CalibrationTarget::Type::kAprilGrid)
    throw std::invalid_argument("only aprilgrid targets can be detected so far");
  ImageDetections image;
  if (!mirrored) {
    for (const auto& [id, corners] : DetectTags(target, grey, stats))
      for (int k = 0; k < 4; ++k) image.corners.push_back({4 * id + k, corners[k]});
    return image;
  }
  cv::Mat flipped;
  cv::flip(grey, flipped, 1);  // undo the mirror's reversal of handedness
  for (const auto& [id, corners] : DetectTags(target, flipped, stats))
    for (int k = 0; k < 4; ++k)  // flip the column back
      image.corners.push_back({4 * id + k, Eigen::Vector2d(grey.cols - 1 - corners[k].x(), corners[k].y())});
  return image;
}

ImageDetections DetectCheckerboard(const CalibrationTarget& target, const cv::Mat& grey,
                                   std::vector<CheckerboardCandidate>* candidates) {
  if (target.type() != CalibrationTarget::Type::kCheckerboard)
    throw std::invalid_argument("not a checkerboard target");
  CheckerboardCandidateOptions options;
  options.mirrored = true;  // undo the mirror's reversal of handedness
  std::vector<CheckerboardCandidate> found = FindCheckerboardCandidates(grey, cv::Size(target.cols(), target.rows()), options);
  const CheckerboardCandidate* best = nullptr;
  for (const CheckerboardCandidate& candidate : found)
    if (candidate.accepted && (!best || candidate.contrast > best->contrast)) best = &candidate;
  ImageDetections image;
  if (best) {
    // findChessboardCornersSB's order on the flipped image: row-major, rows downwards.
    for (int i = 0; i < static_cast<int>(best->grid.corners_px.size()); ++i) {
      const int row_down = i / target.cols(), col = i % target.cols();
      const int id = (target.rows() - 1 - row_down) * target.cols() + col;  // rows counted upwards
      image.corners.push_back({id, best->grid.corners_px[i]});
    }
    std::sort(image.corners.begin(), image.corners.end(),
              [](const CornerObservation& a, const CornerObservation& b) { return a.id < b.id; });
    if (CheckerboardTurnedAround(target, grey, image.corners))
      for (CornerObservation& c : image.corners) c.id = target.cols() * target.rows() - 1 - c.id;
    std::sort(image.corners.begin(), image.corners.end(),
              [](const CornerObservation& a, const CornerObservation& b) { return a.id < b.id; });
  }
  if (candidates) *candidates = std::move(found);
  return image;
}


ImageDetections DetectThroughVirtualViews(const CalibrationTarget& target, const cv::Mat& grey, const Sensor& guess,
                                          const ImageDetections& raw) {
  constexpr int kSize = 400;
  const ProjectionCache& cache = guess.cache();
  // Reference viewpoint on the axis and the omni image's angular scale (px per rad near
  // the middle of the field), from the guess's axial analysis.
  const double viewpoint_z = cache.guess.valid() ? cache.guess.reference_viewpoint_mm() : 0.0;
  const Eigen::Vector3d centre = cache.camera_from_mirror_rotation * Eigen::Vector3d(0, 0, viewpoint_z) +
                                 cache.camera_from_mirror_translation;
  const double omni_px_per_rad = 0.5 * std::min(guess.image_width_px(), guess.image_height_px()) / 2.0;
  const double focal = 2.0 * omni_px_per_rad;  // magnify ~2x
  const double half_fov = std::atan(0.5 * kSize / focal);
  struct Best {
    std::array<Eigen::Vector2d, 4> corners;
    double off_centre;
  };
  std::map<int, Best> best;
  for (double omega = 40.0; omega <= 140.0; omega += 1.6 * half_fov * 180.0 / M_PI) {
    const double omega_rad = omega * M_PI / 180.0;
    const double step = 1.6 * half_fov / std::max(0.2, std::sin(omega_rad));
    for (double azimuth = 0.0; azimuth < 2.0 * M_PI - 1e-9; azimuth += 2.0 * M_PI / std::ceil(2.0 * M_PI / step)) {
      // The view looks outwards along (Omega, azimuth) of the mirror frame, image y down
      // towards the mirror's -z (a proper rotation: no mirror reversal).
      const Eigen::Vector3d forward_m(std::sin(omega_rad) * std::cos(azimuth), std::sin(omega_rad) * std::sin(azimuth),
                                      -std::cos(omega_rad));
      const VirtualView virtual_view(guess, cache.camera_from_mirror_rotation * ViewFrame(forward_m, -Eigen::Vector3d::UnitZ()),
                                     centre, focal, kSize, kSize);
      const cv::Mat view = virtual_view.Resample(grey, cv::INTER_LINEAR);
      for (const auto& [id, corners] : DetectTags(target, view, nullptr)) {
        std::array<Eigen::Vector2d, 4> omni;
        bool inside = true;
        Eigen::Vector2d mean = Eigen::Vector2d::Zero();
        for (int k = 0; k < 4; ++k) {
          inside = inside && virtual_view.ToOmni(corners[k], &omni[k]);
          mean += corners[k] / 4.0;
        }
        if (!inside) continue;
        const double off_centre = (mean - Eigen::Vector2d::Constant(0.5 * (kSize - 1))).norm();
        const auto it = best.find(id);
        if (it == best.end() || off_centre < it->second.off_centre) best[id] = {omni, off_centre};
      }
    }
  }
  ImageDetections out;
  std::map<int, std::array<Eigen::Vector2d, 4>> merged;
  for (size_t k = 0; k + 3 < raw.corners.size(); k += 4)
    if (raw.corners[k].id % 4 == 0)
      merged[raw.corners[k].id / 4] = {raw.corners[k].pixel, raw.corners[k + 1].pixel, raw.corners[k + 2].pixel,
                                       raw.corners[k + 3].pixel};
  for (const auto& [id, b] : best) merged[id] = b.corners;
  for (const auto& [id, corners] : merged)
    for (int k = 0; k < 4; ++k) out.corners.push_back({4 * id + k, corners[k]});
  out.image = raw.image;
  return out;
}

ImageDetections DetectTarget(const CalibrationTarget& target, const cv::Mat& grey) {
  return target.type() == CalibrationTarget::Type::kAprilGrid ? DetectAprilGrid(target, grey)
                                                               : DetectCheckerboard(target, grey);
}

}  // namespace omnical
