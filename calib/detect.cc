#include "calib/detect.h"

#include "calib/aprilgrid_completion.h"
#include "calib/bilinear.h"
#include "calib/partial_checkerboard.h"
#include "calib/virtual_view.h"

#include <Eigen/Geometry>
#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagStandard41h12.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <utility>
#include <stdexcept>

namespace omnical {

namespace {

// One AprilTag detector per thread and family, made on first use: adding a family builds
// its quick-decode table (tens of MB for tag36h11), which cost more than detecting the
// tags of a virtual view when it was made for every call.
class TagDetector {
 public:
  explicit TagDetector(bool tag36h11) : tag36h11_(tag36h11) {
    family_ = tag36h11 ? tag36h11_create() : tagStandard41h12_create();
    detector_ = apriltag_detector_create();
    apriltag_detector_add_family(detector_, family_);
    detector_->quad_decimate = 1.0f;  // full resolution: corners are what calibration needs
    detector_->nthreads = 1;          // images are processed in parallel instead
    detector_->refine_edges = true;
  }
  ~TagDetector() {
    apriltag_detector_destroy(detector_);
    if (tag36h11_) tag36h11_destroy(family_); else tagStandard41h12_destroy(family_);
  }
  TagDetector(const TagDetector&) = delete;
  TagDetector& operator=(const TagDetector&) = delete;

  static apriltag_detector_t* ForThisThread(const std::string& family) {
    const bool tag36h11 = family == "tag36h11";
    thread_local std::unique_ptr<TagDetector> detectors[2];
    std::unique_ptr<TagDetector>& slot = detectors[tag36h11 ? 0 : 1];
    if (!slot) slot = std::make_unique<TagDetector>(tag36h11);
    return slot->detector_;
  }

 private:
  bool tag36h11_;
  apriltag_family_t* family_;
  apriltag_detector_t* detector_;
};

// A tag is decoded from about a pixel a cell at best, and the families' tags are about 10
// cells across with their white border.
constexpr int kMinTagImagePx = 10;

// AprilTag 3 over an image (corners in its pixel-centre coordinates): the target's ids
// only, and an id decoded twice dropped altogether (which copy is the tag is unknown).
std::map<int, std::array<Eigen::Vector2d, 4>> DetectTags(const CalibrationTarget& target, const cv::Mat& image,
                                                         DetectionStats* stats) {
  // AprilTag 3.3 reads out of bounds on images 2 rows high or less (a segfault), and no
  // tag fits in fewer than kMinTagImagePx rows or columns.
  if (stats) *stats = {};
  if (image.rows < kMinTagImagePx || image.cols < kMinTagImagePx) return {};
  apriltag_detector_t* detector = TagDetector::ForThisThread(target.family());
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
  if (corners.empty() || cols < 2 || rows < 2) return false;
  std::map<std::pair<int, int>, Eigen::Vector2d> at;  // (row, col) -> pixel; a partial board has gaps
  for (const CornerObservation& c : corners) at[{c.id / cols, c.id % cols}] = c.pixel;
  if ((cols + rows) % 2 == 1) {
    // At corner (r, c) the squares on the (-x, -y) / (+x, +y) diagonal are dark when r + c
    // is even (corner 0's are), light when odd. Every corner with both neighbours votes,
    // weighted by its contrast: one alone may sit where the rim bends the grid.
    double vote = 0.0;
    int voters = 0;
    for (const auto& [index, corner_px] : at) {
      const Eigen::Vector2d origin = corner_px;  // a lambda may not capture a structured binding (C++17; clang refuses)
      const auto next_col = at.find({index.first, index.second + 1}), next_row = at.find({index.first + 1, index.second});
      if (next_col == at.end() || next_row == at.end()) continue;
      const Eigen::Vector2d along_x = next_col->second - origin, along_y = next_row->second - origin;
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
      if (!std::isfinite(diagonal) || !std::isfinite(other)) continue;
      vote += ((index.first + index.second) % 2 == 0 ? 1.0 : -1.0) * (diagonal - other);
      ++voters;
    }
    if (voters > 0) return vote > 0.0;
  }
  // Up: along each column from its lowest corner seen to its highest.
  Eigen::Vector2d centre = Eigen::Vector2d::Zero(), up = Eigen::Vector2d::Zero();
  for (const CornerObservation& c : corners) centre += c.pixel / corners.size();
  for (int col = 0; col < cols; ++col) {
    const Eigen::Vector2d* lowest = nullptr;
    const Eigen::Vector2d* highest = nullptr;
    for (int row = 0; row < rows; ++row)
      if (const auto it = at.find({row, col}); it != at.end()) {
        if (!lowest) lowest = &it->second;
        highest = &it->second;
      }
    if (lowest) up += *highest - *lowest;
  }
  const Eigen::Vector2d image_centre(0.5 * (grey.cols - 1), 0.5 * (grey.rows - 1));
  return up.dot(centre - image_centre) < 0.0;
}

// A found board's corners (row_down, col: findChessboardCornersSB's order in an image of
// normal handedness, the flipped omni image or a virtual view; omni pixels) with the
// board's ids, rows counted upwards, and the 180 deg turn resolved on the omni image.
std::vector<CornerObservation> CheckerboardCorners(const CalibrationTarget& target, const cv::Mat& omni_grey,
                                                   const std::vector<BoardCorner>& found) {
  std::vector<CornerObservation> corners;
  for (const BoardCorner& c : found) corners.push_back({(target.rows() - 1 - c.row_down) * target.cols() + c.col, c.pixel});
  auto by_id = [](const CornerObservation& a, const CornerObservation& b) { return a.id < b.id; };
  std::sort(corners.begin(), corners.end(), by_id);
  if (CheckerboardTurnedAround(target, omni_grey, corners))
    for (CornerObservation& c : corners) c.id = target.cols() * target.rows() - 1 - c.id;
  std::sort(corners.begin(), corners.end(), by_id);
  return corners;
}

// A complete grid (row-major, rows downwards) as board corners.
std::vector<BoardCorner> BoardCorners(const std::vector<Eigen::Vector2d>& grid_px, int cols) {
  std::vector<BoardCorner> corners;
  for (int i = 0; i < static_cast<int>(grid_px.size()); ++i) corners.push_back({i / cols, i % cols, grid_px[i]});
  return corners;
}

// The omni image's angular scale near the middle of the field (px per rad), roughly: a
// quarter of the image per radian.
double OmniPxPerRad(const Sensor& guess) {
  return 0.5 * std::min(guess.image_width_px(), guess.image_height_px()) / 2.0;
}

// A sweep of views looking outwards along (Omega, azimuth) of the mirror frame, Omega
// 40-140 deg from its -z (a proper rotation: no mirror reversal), neighbours
// step_fraction of a view's half field apart. visit(view) returns false to stop.
void SweepVirtualViews(const Sensor& guess, int size_px, double focal_px, double step_fraction,
                       const std::function<bool(const VirtualView&)>& visit) {
  const Eigen::Matrix3d& mirror_to_camera = guess.cache().camera_from_mirror_rotation;
  const double half_fov = std::atan(0.5 * size_px / focal_px);
  for (double omega = 40.0; omega <= 140.0; omega += step_fraction * half_fov * 180.0 / M_PI) {
    const double omega_rad = omega * M_PI / 180.0;
    const double step = step_fraction * half_fov / std::max(0.2, std::sin(omega_rad));
    for (double azimuth = 0.0; azimuth < 2.0 * M_PI - 1e-9; azimuth += 2.0 * M_PI / std::ceil(2.0 * M_PI / step)) {
      const Eigen::Vector3d forward_m(std::sin(omega_rad) * std::cos(azimuth), std::sin(omega_rad) * std::sin(azimuth),
                                      -std::cos(omega_rad));
      if (!visit(ViewAlong(guess, mirror_to_camera * forward_m, size_px, focal_px))) return;
    }
  }
}

// The board, or a part of it, in a view (calib/partial_checkerboard.h), its corners in
// omni pixels, and the direction of its centre (camera frame). A corner with a point 0.7
// of a grid step away along the view's diagonals outside the mirror's image is dropped:
// there its position is pulled by the rim's edge, not the board's (a rim corner of the
// realistic render came out 4.6 px off when probing 0.4 of a step).
std::optional<PartialCheckerboard> CheckerboardInView(const CalibrationTarget& target, const cv::Mat& grey,
                                                      const VirtualView& virtual_view, Eigen::Vector3d* direction) {
  const cv::Mat view = virtual_view.Resample(grey, cv::INTER_LINEAR);
  std::optional<PartialCheckerboard> found = FindPartialCheckerboard(view, cv::Size(target.cols(), target.rows()));
  if (!found) return std::nullopt;
  *direction = Eigen::Vector3d::Zero();
  std::vector<BoardCorner> omni;
  for (const BoardCorner& corner : found->corners) {
    *direction += virtual_view.Direction(corner.pixel);
    double step_px = HUGE_VAL;
    for (const BoardCorner& other : found->corners)
      if (&other != &corner) step_px = std::min(step_px, (other.pixel - corner.pixel).norm());
    BoardCorner mapped = corner;
    bool inside = virtual_view.ToOmni(corner.pixel, &mapped.pixel);
    Eigen::Vector2d unused;
    for (const Eigen::Vector2d& offset : {Eigen::Vector2d(1, 1), Eigen::Vector2d(1, -1), Eigen::Vector2d(-1, 1), Eigen::Vector2d(-1, -1)})
      inside = inside && virtual_view.ToOmni(corner.pixel + 0.7 * step_px / std::sqrt(2.0) * offset, &unused);
    if (inside) omni.push_back(mapped);
  }
  direction->normalize();
  // A junction squeezed under kMinOmniStepPx between grid neighbours in the omni image
  // (the sphere's rim compresses the radial direction) is a blur of JPEG blocks there: its
  // corner is not located to a pixel (a render's corners at 498-515 px from the centre of
  // a 520 px disc: 4-5 px off). Such corners are dropped.
  constexpr double kMinOmniStepPx = 3.0;
  std::vector<BoardCorner> kept;
  for (const BoardCorner& corner : omni) {
    double nearest_px = HUGE_VAL;
    for (const BoardCorner& other : omni)
      if (std::abs(other.row_down - corner.row_down) + std::abs(other.col - corner.col) == 1)
        nearest_px = std::min(nearest_px, (other.pixel - corner.pixel).norm());
    if (nearest_px >= kMinOmniStepPx) kept.push_back(corner);
  }
  found->corners = std::move(kept);
  return found;
}

// A board the omni image's search missed (strongly curved near the rim or the inner
// radius, or cut by the rim), searched in wide views (90 deg, about the omni image's own
// scale at their centre) where it is nearly straight. A board found there, or a part cut
// by a view's edge, is searched again in a wider view (116 deg) aimed at its centre, where
// it is whole and least stretched; a placed board from either is kept, the one with more
// corners.
ImageDetections CheckerboardThroughVirtualViews(const CalibrationTarget& target, const cv::Mat& grey, const Sensor& guess,
                                               const ImageDetections& raw) {
  const int size_px = static_cast<int>(std::lround(2.5 * OmniPxPerRad(guess)));
  const double focal_px = 0.5 * size_px;  // 90 deg across
  std::vector<BoardCorner> best;
  SweepVirtualViews(guess, size_px, focal_px, 1.0, [&](const VirtualView& view) {
    Eigen::Vector3d direction;
    const std::optional<PartialCheckerboard> found = CheckerboardInView(target, grey, view, &direction);
    if (!found) return true;
    if (found->placed && found->corners.size() > best.size()) best = found->corners;
    Eigen::Vector3d aimed_direction;
    const std::optional<PartialCheckerboard> aimed = CheckerboardInView(
        target, grey, ViewAlong(guess, direction, static_cast<int>(1.6 * size_px), focal_px), &aimed_direction);
    if (aimed && aimed->placed && aimed->corners.size() >= best.size()) best = aimed->corners;
    return best.size() < 4;  // on: the rim may have left too few corners for a pose
  });
  ImageDetections out;
  out.image = raw.image;
  if (!best.empty()) out.corners = CheckerboardCorners(target, grey, best);
  return out;
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
    const CheckedGrid checked = CheckGridJunctions(grey, best->grid, options.junction_contrast_fraction * best->contrast);
    std::vector<BoardCorner> corners;
    const std::vector<BoardCorner> all = BoardCorners(checked.corners_px, target.cols());
    for (size_t k = 0; k < all.size(); ++k)
      if (checked.kept[k]) corners.push_back(all[k]);
    image.corners = CheckerboardCorners(target, grey, corners);
  }
  if (candidates) *candidates = std::move(found);
  return image;
}

ImageDetections DetectThroughVirtualViews(const CalibrationTarget& target, const cv::Mat& grey, const Sensor& guess,
                                          const ImageDetections& raw) {
  if (target.type() == CalibrationTarget::Type::kCheckerboard)
    return raw.corners.empty() ? CheckerboardThroughVirtualViews(target, grey, guess, raw) : raw;
  constexpr int kSize = 400;
  const double focal = 2.0 * OmniPxPerRad(guess);  // magnify ~2x
  struct Best {
    std::array<Eigen::Vector2d, 4> corners;
    double off_centre;
  };
  std::map<int, Best> best;
  SweepVirtualViews(guess, kSize, focal, 1.6, [&](const VirtualView& virtual_view) {
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
    return true;
  });
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
  return CompleteAprilGrid(target, grey, guess, out);
}

ImageDetections DetectTarget(const CalibrationTarget& target, const cv::Mat& grey) {
  return target.type() == CalibrationTarget::Type::kAprilGrid ? DetectAprilGrid(target, grey)
                                                               : DetectCheckerboard(target, grey);
}

}  // namespace omnical
