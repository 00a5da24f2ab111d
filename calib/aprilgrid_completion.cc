#include "calib/aprilgrid_completion.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include "calib/bilinear.h"
#include "calib/virtual_view.h"

namespace omnical {
namespace {

constexpr int kMinDecodedTags = 4;

// Black square minus white gap, in grey levels, of the tag whose black square's
// bottom-left corner is at `low_mm` (board frame): samples a sixteenth of the square inside
// its edges (the border cells, black on every tag) against half the gap outside them,
// through the board -> view homography. NaN where a sample leaves the view.
double BorderContrast(const cv::Mat& view, const cv::Mat& board_to_view, const Eigen::Vector2d& low_mm, double size_mm,
                      double gap_mm) {
  std::vector<cv::Point2f> inside, outside;
  for (int k = 1; k <= 7; ++k) {
    const double t = size_mm * k / 8.0;
    for (const auto& [in, out] : std::array<std::pair<Eigen::Vector2d, Eigen::Vector2d>, 4>{{
             {{t, size_mm / 16.0}, {t, -gap_mm / 2.0}},
             {{t, size_mm - size_mm / 16.0}, {t, size_mm + gap_mm / 2.0}},
             {{size_mm / 16.0, t}, {-gap_mm / 2.0, t}},
             {{size_mm - size_mm / 16.0, t}, {size_mm + gap_mm / 2.0, t}},
         }}) {
      inside.emplace_back(static_cast<float>(low_mm.x() + in.x()), static_cast<float>(low_mm.y() + in.y()));
      outside.emplace_back(static_cast<float>(low_mm.x() + out.x()), static_cast<float>(low_mm.y() + out.y()));
    }
  }
  cv::perspectiveTransform(inside, inside, board_to_view);
  cv::perspectiveTransform(outside, outside, board_to_view);
  double dark = 0.0, light = 0.0;
  for (size_t i = 0; i < inside.size(); ++i) {
    const double a = Bilinear<uchar>(view, inside[i].x, inside[i].y), b = Bilinear<uchar>(view, outside[i].x, outside[i].y);
    if (!std::isfinite(a) || !std::isfinite(b) || a == 0.0 || b == 0.0) return NAN;  // 0: beyond the mirror
    dark += a, light += b;
  }
  return (light - dark) / inside.size();
}

}  // namespace

ImageDetections CompleteAprilGrid(const CalibrationTarget& target, const cv::Mat& grey, const Sensor& guess,
                                  const ImageDetections& found) {
  // tagStandard41h12's quad is white inside its black ring: the border test below reads
  // tag36h11's black square.
  if (target.type() != CalibrationTarget::Type::kAprilGrid || target.family() != "tag36h11") return found;
  std::map<int, Eigen::Vector3d> board_mm;
  for (const TargetCorner& c : target.corners()) board_mm[c.id] = c.point_in_target;
  std::set<int> decoded;
  for (const CornerObservation& c : found.corners) decoded.insert(c.id / 4);
  const int tags = target.cols() * target.rows();
  if (static_cast<int>(decoded.size()) < kMinDecodedTags || static_cast<int>(decoded.size()) == tags) return found;

  // A view aimed at the decoded corners, wide enough for the board around them.
  std::vector<Eigen::Vector3d> directions(found.corners.size());
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < found.corners.size(); ++i) {
    Eigen::Vector3d origin;
    if (guess.Unproject(found.corners[i].pixel, &origin, &directions[i]) != ProjectionStatus::kOk) return found;
    mean += directions[i].normalized();
  }
  mean.normalize();
  double spread_rad = 0.0;
  for (const Eigen::Vector3d& d : directions) spread_rad = std::max(spread_rad, std::acos(std::clamp(d.normalized().dot(mean), -1.0, 1.0)));
  const double half_fov_rad = std::min(70.0 * M_PI / 180.0, 2.0 * spread_rad + 5.0 * M_PI / 180.0);
  constexpr int kSizePx = 800;
  const double focal_px = 0.5 * kSizePx / std::tan(half_fov_rad);
  const VirtualView view = ViewAlong(guess, mean, kSizePx, focal_px);

  // Each decoded tag's corners in the view.
  std::map<int, std::array<cv::Point2f, 4>> in_view;  // tag -> corners 0-3
  std::map<int, int> mapped_corners;
  for (size_t i = 0; i < found.corners.size(); ++i) {
    Eigen::Vector2d view_px;
    if (!view.FromOmni(found.corners[i].pixel, view.ToView(directions[i]), &view_px)) continue;
    const int id = found.corners[i].id;
    in_view[id / 4][id % 4] = cv::Point2f(static_cast<float>(view_px.x()), static_cast<float>(view_px.y()));
    ++mapped_corners[id / 4];
  }
  for (auto it = mapped_corners.begin(); it != mapped_corners.end(); ++it)
    if (it->second != 4) in_view.erase(it->first);
  if (static_cast<int>(in_view.size()) < kMinDecodedTags) return found;

  const cv::Mat image = view.Resample(grey, cv::INTER_LINEAR);
  const double size_mm = target.tag_size_mm(), gap_mm = target.spacing_ratio() * size_mm;
  auto low_of = [&](int tag) { return Eigen::Vector2d(board_mm.at(4 * tag).head<2>()); };  // corner 0: bottom-left
  // The board -> view homography near a tag, from the kNeighbours known tags nearest to it
  // on the board: the view is a true perspective image only as far as the guess is right,
  // so a board-wide homography drifts by pixels towards the rim; a local one follows.
  constexpr size_t kNeighbours = 6;
  auto local_homography = [&](int tag) {
    std::vector<std::pair<double, int>> by_distance;
    for (const auto& [known, corners] : in_view) by_distance.push_back({(low_of(known) - low_of(tag)).norm(), known});
    std::sort(by_distance.begin(), by_distance.end());
    std::vector<cv::Point2f> board_points, view_points;
    for (size_t n = 0; n < std::min(kNeighbours, by_distance.size()); ++n)
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector3d& p = board_mm.at(4 * by_distance[n].second + k);
        board_points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
        view_points.push_back(in_view.at(by_distance[n].second)[k]);
      }
    return cv::findHomography(board_points, view_points, 0);
  };
  std::vector<double> contrasts;
  for (const auto& [tag, corners] : in_view) {
    const cv::Mat homography = local_homography(tag);
    if (homography.empty()) continue;
    if (const double c = BorderContrast(image, homography, low_of(tag), size_mm, gap_mm); std::isfinite(c))
      contrasts.push_back(c);
  }
  if (contrasts.empty()) return found;
  std::nth_element(contrasts.begin(), contrasts.begin() + contrasts.size() / 2, contrasts.end());
  const double threshold = 0.5 * contrasts[contrasts.size() / 2];
  if (!(threshold > 0.0)) return found;

  // Outwards from the decoded tags, a ring at a time: an unread tag next to a known one
  // (on the board's grid) is predicted, checked, and known from then on.
  ImageDetections out = found;
  auto grid_neighbour_known = [&](int tag) {
    const int index = tag - target.code_offset(), row = index / target.cols(), col = index % target.cols();
    for (const auto& [dr, dc] : std::array<std::pair<int, int>, 4>{{{1, 0}, {-1, 0}, {0, 1}, {0, -1}}}) {
      const int r = row + dr, c = col + dc;
      if (r >= 0 && r < target.rows() && c >= 0 && c < target.cols() && in_view.count(target.code_offset() + r * target.cols() + c))
        return true;
    }
    return false;
  };
  std::set<int> refused;
  for (bool grew = true; grew;) {
    grew = false;
    std::map<int, std::array<cv::Point2f, 4>> ring;
    for (int tag = target.code_offset(); tag < target.code_offset() + tags; ++tag) {
      if (decoded.count(tag) || in_view.count(tag) || refused.count(tag) || !grid_neighbour_known(tag)) continue;
      const cv::Mat homography = local_homography(tag);
      if (homography.empty() || !(BorderContrast(image, homography, low_of(tag), size_mm, gap_mm) > threshold)) {
        refused.insert(tag);
        continue;
      }
      std::vector<cv::Point2f> corners;
      for (int k = 0; k < 4; ++k)
        corners.emplace_back(static_cast<float>(board_mm.at(4 * tag + k).x()), static_cast<float>(board_mm.at(4 * tag + k).y()));
      cv::perspectiveTransform(corners, corners, homography);
      std::array<Eigen::Vector2d, 4> omni;
      bool inside = true;
      for (int k = 0; k < 4 && inside; ++k) inside = view.ToOmni(Eigen::Vector2d(corners[k].x, corners[k].y), &omni[k]);
      if (!inside) {
        refused.insert(tag);
        continue;
      }
      for (int k = 0; k < 4; ++k) out.corners.push_back({4 * tag + k, omni[k]});
      ring[tag] = {corners[0], corners[1], corners[2], corners[3]};
    }
    for (const auto& [tag, corners] : ring) in_view[tag] = corners, grew = true;
  }
  std::sort(out.corners.begin(), out.corners.end(),
            [](const CornerObservation& a, const CornerObservation& b) { return a.id < b.id; });
  return out;
}

}  // namespace omnical
