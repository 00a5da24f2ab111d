#include "calib/refine_corners.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>

#include "calib/bilinear.h"
#include "calib/checker_junction_fit.h"
#include "calib/tag_template_fit.h"
#include "calib/virtual_view.h"

namespace omnical {

namespace {

constexpr double kMagnification = 2.0;     // patch px per omni px (at least, along both axes)
constexpr double kMinNeighbourPx = 64.0;  // aprilgrid: 8 px border cells; checkerboard: a 25 px window

// The corner ids next to `id` along the target's edges (aprilgrid: the two other corners
// of its tag's black square; checkerboard: up to four grid neighbours).
std::vector<int> NeighboursOf(const CalibrationTarget& target, int id) {
  if (target.type() == CalibrationTarget::Type::kAprilGrid) {
    const int tag = id / 4, k = id % 4;
    return {4 * tag + (k + 1) % 4, 4 * tag + (k + 3) % 4};
  }
  const int cols = target.cols(), rows = target.rows(), row = id / cols, col = id % cols;
  std::vector<int> neighbours;
  if (col > 0) neighbours.push_back(id - 1);
  if (col + 1 < cols) neighbours.push_back(id + 1);
  if (row > 0) neighbours.push_back(id - cols);
  if (row + 1 < rows) neighbours.push_back(id + cols);
  return neighbours;
}

// cornerSubPix from `start` with half window `window_px`; false if it wandered off (more
// than half the window: it found another edge, not this corner).
bool SubPixel(const cv::Mat& image, const Eigen::Vector2d& start, double window_px, Eigen::Vector2d* refined) {
  const int half = static_cast<int>(std::floor(window_px));
  if (half < 2) return false;
  std::vector<cv::Point2f> point{cv::Point2f(static_cast<float>(start.x()), static_cast<float>(start.y()))};
  if (start.x() < half + 2 || start.y() < half + 2 || start.x() > image.cols - half - 3 || start.y() > image.rows - half - 3)
    return false;
  cv::cornerSubPix(image, point, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
  *refined = Eigen::Vector2d(point[0].x, point[0].y);
  return std::isfinite(refined->x()) && std::isfinite(refined->y()) && (*refined - start).norm() <= 0.5 * half;
}

double Sample(const cv::Mat& image, const Eigen::Vector2d& at) { return Bilinear<uint8_t>(image, at.x(), at.y()); }

// An edge profile: the image along base + s * normal at kProfileSamples values of s from
// from_px to to_px (in that order). False where it leaves the image.
constexpr int kProfileSamples = 41;
struct EdgeProfile {
  double from_px, to_px;
  double values[kProfileSamples];
  double Step() const { return (to_px - from_px) / (kProfileSamples - 1); }
  double S(int k) const { return from_px + Step() * k; }
  // The mean over the samples with s in [low_px, high_px].
  double Mean(double low_px, double high_px) const {
    double sum = 0.0;
    int count = 0;
    for (int k = 0; k < kProfileSamples; ++k)
      if (S(k) >= low_px && S(k) <= high_px) sum += values[k], ++count;
    return sum / std::max(1, count);
  }
  // Where the profile crosses `level`, nearest to s = 0 (not finite if it never does).
  double CrossingNearestZero(double level) const {
    double best = HUGE_VAL;
    for (int k = 0; k + 1 < kProfileSamples; ++k) {
      const double a = values[k] - level, b = values[k + 1] - level;
      if (a * b > 0.0 || a == b) continue;
      const double s = from_px + Step() * (k + a / (a - b));
      if (std::abs(s) < std::abs(best)) best = s;
    }
    return best;
  }
};
bool SampleProfile(const cv::Mat& image, const Eigen::Vector2d& base, const Eigen::Vector2d& normal, double from_px,
                   double to_px, EdgeProfile* profile) {
  profile->from_px = from_px;
  profile->to_px = to_px;
  for (int k = 0; k < kProfileSamples; ++k)
    if (profile->values[k] = Sample(image, base + profile->S(k) * normal); !std::isfinite(profile->values[k])) return false;
  return true;
}

// Crossings (t along an edge, s across it) fitted by the line s = a + b t (least squares);
// scatter: their RMS about it.
struct EdgeFit {
  double a = 0.0, b = 0.0, scatter = 0.0;
};
EdgeFit FitEdgeLine(const std::vector<double>& ts, const std::vector<double>& ss) {
  double mt = 0, ms = 0, stt = 0, sts = 0;
  for (size_t i = 0; i < ts.size(); ++i) mt += ts[i], ms += ss[i];
  mt /= ts.size();
  ms /= ts.size();
  for (size_t i = 0; i < ts.size(); ++i) stt += (ts[i] - mt) * (ts[i] - mt), sts += (ts[i] - mt) * (ss[i] - ms);
  EdgeFit fit;
  fit.b = sts / stt;
  fit.a = ms - fit.b * mt;
  for (size_t i = 0; i < ts.size(); ++i) fit.scatter += std::pow(ss[i] - fit.a - fit.b * ts[i], 2);
  fit.scatter = std::sqrt(fit.scatter / ts.size());
  return fit;
}

// Crossings fitted by the parabola s = a + b t + c t^2 (least squares): a and b the curve's
// offset and slope at t = 0; scatter: their RMS about it. t is scaled by its largest value
// for the solve (a patch's t reach hundreds of px: the normal equations' condition grows
// as t^4).
EdgeFit FitEdgeCurve(const std::vector<double>& ts, const std::vector<double>& ss) {
  double scale = 0.0;
  for (double t : ts) scale = std::max(scale, std::abs(t));
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d right = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < ts.size(); ++i) {
    const double u = ts[i] / scale;
    const Eigen::Vector3d row(1.0, u, u * u);
    normal += row * row.transpose();
    right += row * ss[i];
  }
  const Eigen::Vector3d abc = normal.ldlt().solve(right);
  EdgeFit fit;
  fit.a = abc[0];
  fit.b = abc[1] / scale;
  for (size_t i = 0; i < ts.size(); ++i) {
    const double u = ts[i] / scale;
    fit.scatter += std::pow(ss[i] - abc[0] - abc[1] * u - abc[2] * u * u, 2);
  }
  fit.scatter = std::sqrt(fit.scatter / ts.size());
  return fit;
}

// Where point[0] + u direction[0] meets point[1] + v direction[1] (unit directions); false
// when the sine of their angle is under min_sine.
bool IntersectLines(const Eigen::Vector2d (&point)[2], const Eigen::Vector2d (&direction)[2], double min_sine,
                    Eigen::Vector2d* at) {
  Eigen::Matrix2d m;
  m << direction[0], -direction[1];
  if (std::abs(m.determinant()) < min_sine) return false;
  *at = point[0] + (m.inverse() * (point[1] - point[0])).x() * direction[0];
  return true;
}

// Where an edge crosses the profile base + s * normal, s from -inside_px (ink) to
// +outside_px (paper): the crossing of the level halfway between the ink level and the
// paper plateau (unbiased for any symmetric blur), nearest to s = 0. The ink level comes
// from the caller: inside a small tag the border cell is too thin to show a plateau of its
// own. False on a weak or missing edge.
bool EdgeCrossing(const cv::Mat& image, const Eigen::Vector2d& base, const Eigen::Vector2d& normal, double inside_px,
                  double outside_px, double ink, double* crossing) {
  EdgeProfile profile;
  if (!SampleProfile(image, base, normal, -inside_px, outside_px, &profile)) return false;
  const double paper = profile.Mean(0.6 * outside_px, HUGE_VAL);
  if (paper - ink < 20.0) return false;
  *crossing = profile.CrossingNearestZero(0.5 * (ink + paper));
  return std::isfinite(*crossing);
}

// An aprilgrid corner is the convex corner of a black square on the white gap, where a
// gradient-orthogonality window is biased (the blurred tip's gradients point along the
// bisector). Instead each of the two edges is located along profiles across it, from 0.5
// to 7 border cells from the corner (0.8 cell inside, 1.6 cells into the 2.4-cell gap),
// fitted by a line, and the lines intersected; twice, the second time along the fitted
// edges. Nearly the whole side averages the noise. The edges must be straight where they
// are fitted: in a patch through the guess they are, to the extent that the guess is right
// and the patch sits at the board's depth (below).
bool RefineSquareCorner(const cv::Mat& image, const Eigen::Vector2d& start, const Eigen::Vector2d (&towards)[2],
                        double cell_px, Eigen::Vector2d* refined) {
  if (cell_px < 1.5) return false;
  Eigen::Vector2d corner = start, edge[2] = {towards[0].normalized(), towards[1].normalized()};
  // Ink level: the median along the middle of the square's black border cells (half a cell
  // in from both edges). Not a dark percentile of the whole interior: the bicubic patch
  // undershoots next to every edge, the data cells' ones included, and a level pulled down
  // that way put every edge ~0.02 px inside the square on renders (tags measured small).
  std::vector<double> border;
  for (int e = 0; e < 2; ++e)
    for (double t = 1.0; t <= 7.0; t += 0.25)
      if (const double v = Sample(image, start + cell_px * (t * edge[e] + 0.5 * edge[1 - e])); std::isfinite(v))
        border.push_back(v);
  if (border.size() < 20) return false;
  std::nth_element(border.begin(), border.begin() + border.size() / 2, border.end());
  const double ink = border[border.size() / 2];
  for (int pass = 0; pass < 2; ++pass) {
    Eigen::Vector2d point[2], direction[2];
    for (int e = 0; e < 2; ++e) {
      // Normal pointing out of the square: away from the other edge.
      Eigen::Vector2d normal(-edge[e].y(), edge[e].x());
      if (normal.dot(edge[1 - e]) > 0.0) normal = -normal;
      std::vector<double> ts, ss;
      for (double t = 0.5 * cell_px; t <= 7.0 * cell_px; t += 0.5)
        if (double s; EdgeCrossing(image, corner + t * edge[e], normal, 0.8 * cell_px, 1.6 * cell_px, ink, &s))
          ts.push_back(t), ss.push_back(s);
      if (ts.size() < 4) return false;
      const EdgeFit line = FitEdgeLine(ts, ss);
      // A straight edge fits its crossings to a small fraction of a cell; crossings
      // scattered over the profile mean the start was off the corner (another edge, the
      // data bits): keep the detector's point.
      const double profiles = (7.0 - 0.5) * cell_px / 0.5;
      if (line.scatter > 0.1 * cell_px || ts.size() < 0.6 * profiles) return false;
      point[e] = corner + line.a * normal;
      direction[e] = (edge[e] + line.b * normal).normalized();
    }
    if (!IntersectLines(point, direction, 0.2, &corner)) return false;  // edges nearly parallel: not a corner
    edge[0] = direction[0];
    edge[1] = direction[1];
  }
  if ((corner - start).norm() > 0.5 * cell_px) return false;
  *refined = corner;
  return true;
}

// Where the edge between two squares crosses base + s * normal, s in [-half_px, half_px]:
// the crossing of the level halfway between the plateaus at both ends (the outer 40 %),
// nearest to s = 0. False on a weak edge (under 20 grey levels).
bool JunctionEdgeCrossing(const cv::Mat& image, const Eigen::Vector2d& base, const Eigen::Vector2d& normal,
                          double half_px, double* crossing) {
  EdgeProfile profile;
  if (!SampleProfile(image, base, normal, -half_px, half_px, &profile)) return false;
  const double low = profile.Mean(-HUGE_VAL, -0.6 * half_px), high = profile.Mean(0.6 * half_px, HUGE_VAL);
  if (std::abs(high - low) < 20.0) return false;
  *crossing = profile.CrossingNearestZero(0.5 * (low + high));
  return std::isfinite(*crossing);
}

// CheckerRefinement::kEdges (calib/refine_corners.h): a checkerboard corner is where two
// edges cross, each running through the corner between two squares (its contrast flips
// there), located along profiles across it on both sides, fitted by a parabola, and the
// tangents at the corner intersected; twice, the second time along the fitted tangents.
bool RefineCheckerJunction(const cv::Mat& image, const Eigen::Vector2d& start, const std::vector<Eigen::Vector2d>& neighbours,
                           double square_px, Eigen::Vector2d* refined) {
  if (neighbours.size() < 2 || square_px < 8.0) return false;
  // The two grid lines: towards the first neighbour, and the neighbour most across it.
  Eigen::Vector2d line[2] = {(neighbours[0] - start).normalized(), Eigen::Vector2d::Zero()};
  double across = 0.0;
  for (size_t k = 1; k < neighbours.size(); ++k) {
    const Eigen::Vector2d d = (neighbours[k] - start).normalized();
    const double sine = std::abs(line[0].x() * d.y() - line[0].y() * d.x());
    if (sine > across) across = sine, line[1] = d;
  }
  if (across < 0.5) return false;  // grid lines within 30 deg of each other: not a junction we can read
  Eigen::Vector2d corner = start;
  for (int pass = 0; pass < 2; ++pass) {
    Eigen::Vector2d point[2], direction[2];
    for (int e = 0; e < 2; ++e) {
      const Eigen::Vector2d normal(-line[e].y(), line[e].x());
      std::vector<double> ts, ss;
      int per_side[2] = {0, 0};
      for (double t = 0.25 * square_px; t <= 0.85 * square_px; t += 0.5)
        for (int side = 0; side < 2; ++side) {
          const double signed_t = side == 0 ? -t : t;
          // Profiles reach across this edge only as far as the other grid line allows.
          const double half_px = std::min(0.45 * square_px, 0.7 * t * across);
          if (double s; JunctionEdgeCrossing(image, corner + signed_t * line[e], normal, half_px, &s))
            ts.push_back(signed_t), ss.push_back(s), ++per_side[side];
        }
      // Both sides: the junction's blur is odd about the corner and cancels in the offset
      // only when both are there (one side lost to the rim or an occluder: keep the point).
      const double profiles_per_side = (0.85 - 0.25) * square_px / 0.5;
      if (per_side[0] < 0.4 * profiles_per_side || per_side[1] < 0.4 * profiles_per_side ||
          ts.size() < 1.2 * profiles_per_side)
        return false;
      const EdgeFit fit = FitEdgeCurve(ts, ss);
      // Crossings scattered over the profile: the start was off the junction, or the edge
      // is not there (the rim, an occluder): keep the detector's point.
      if (fit.scatter > 0.05 * square_px) return false;
      point[e] = corner + fit.a * normal;
      direction[e] = (line[e] + fit.b * normal).normalized();
    }
    if (!IntersectLines(point, direction, 0.5, &corner)) return false;
    line[0] = direction[0];
    line[1] = direction[1];
  }
  if (!((corner - start).norm() <= 0.25 * square_px)) return false;  // NaN too
  *refined = corner;
  return true;
}

// Refines one corner in `image` given its neighbours' positions there. Returns false
// where the detector's position is kept. `by_edges`: a checkerboard's by its edges (only
// in a patch through a guess, where they are nearly straight; on the omni image they
// curve).
bool RefineInImage(const CalibrationTarget& target, const cv::Mat& image, const Eigen::Vector2d& start,
                   const std::vector<Eigen::Vector2d>& neighbours, bool by_edges, Eigen::Vector2d* refined) {
  double distance = HUGE_VAL;
  for (const Eigen::Vector2d& n : neighbours) distance = std::min(distance, (n - start).norm());
  if (!std::isfinite(distance)) return false;
  if (target.type() == CalibrationTarget::Type::kCheckerboard) {
    if (by_edges) return RefineCheckerJunction(image, start, neighbours, distance, refined);
    return SubPixel(image, start, 0.4 * distance, refined);  // 0.4 square keeps off the next corners' edges
  }
  // tagStandard41h12 has data bits outside its black square: no clean edge profile there.
  if (target.family() != "tag36h11" || neighbours.size() != 2) return false;
  const Eigen::Vector2d towards[2] = {neighbours[0] - start, neighbours[1] - start};
  return RefineSquareCorner(image, start, towards, distance / 8.0, refined);  // 8 cells across the black square
}

// Whether the patch shows the mirror within radius_px of `centre`: the patch is 0 beyond
// the rim, which edge profiles read as ink (a predicted junction 4.5 px inside the rim of
// the realistic checkerboard render went 2.6 px off along the rim's edge). The circle's
// edge is enough: the rim, or the camera's reflection, is far wider than a patch, so it
// crosses the circle before it lies inside.
bool ClearOfRim(const VirtualView& patch, const Eigen::Vector2d& centre, double radius_px) {
  Eigen::Vector2d omni_px;
  const int steps = static_cast<int>(std::ceil(2.0 * M_PI * radius_px));  // 1 patch px apart
  for (int k = 0; k < steps; ++k) {
    const double angle = 2.0 * M_PI * k / steps;
    if (!patch.ToOmni(centre + radius_px * Eigen::Vector2d(std::cos(angle), std::sin(angle)), &omni_px)) return false;
  }
  return patch.ToOmni(centre, &omni_px);
}

// The margin a refinement needs around the corner, in neighbour distances.
double ReachOf(const CalibrationTarget& target, CheckerRefinement checker_refinement) {
  if (target.type() != CalibrationTarget::Type::kCheckerboard) return (7.0 + 0.8) / 8.0;
  return checker_refinement == CheckerRefinement::kEdges ? 0.85 + 0.45 : 0.5;
}

}  // namespace

ImageDetections RefineCorners(const CalibrationTarget& target, const cv::Mat& grey, const Sensor* guess,
                              const ImageDetections& detections, CornerRefinementStats* stats,
                              double min_checker_step_px, CheckerRefinement checker_refinement, bool fit_whole_tags,
                              const BoardWarp& warp) {
  const bool by_edges = guess && checker_refinement == CheckerRefinement::kEdges;
  CornerRefinementStats local;
  std::map<int, Eigen::Vector2d> by_id;
  std::map<int, Eigen::Vector2d> detected_px;  // without the predictions
  for (const CornerObservation& c : detections.corners) {
    by_id[c.id] = c.pixel;
    if (!c.predicted) detected_px[c.id] = c.pixel;
  }
  // Rays of every corner (with a guess): the patch of a corner looks along its own ray,
  // and its neighbours' rays place them in the patch.
  std::map<int, std::pair<Eigen::Vector3d, Eigen::Vector3d>> rays;
  if (guess)
    for (const auto& [id, pixel] : by_id) {
      Eigen::Vector3d origin, direction;
      if (guess->Unproject(pixel, &origin, &direction) == ProjectionStatus::kOk) rays[id] = {origin, direction};
    }

  std::map<int, Eigen::Vector3d> board_mm;
  for (const TargetCorner& c : target.corners()) board_mm[c.id] = c.point_in_target;

  ImageDetections out = detections;
  out.corners.clear();
  for (CornerObservation corner : detections.corners) {
    // A tag's predicted corners stand or fall with the tag's fit across the rim (below).
    if (corner.predicted && target.type() == CalibrationTarget::Type::kAprilGrid) {
      out.corners.push_back(corner);
      continue;
    }
    const std::vector<int> neighbour_ids = NeighboursOf(target, corner.id);
    // A prediction (calib/checkerboard_completion.h) by its edges in either mode: it stands
    // only where they, or the squares fitted whole, show a junction.
    const bool corner_by_edges = by_edges || (guess && corner.predicted);
    bool moved = false;
    Eigen::Vector2d refined;
    bool small_square = false;
    // Small squares: left to the detector for cornerSubPix (its window holds too few
    // pixels there), not for the edge fits (they run over a magnified square).
    if (target.type() == CalibrationTarget::Type::kCheckerboard && min_checker_step_px > 0.0 && !corner_by_edges) {
      double omni_step_px = HUGE_VAL;
      for (int n : neighbour_ids)
        if (detected_px.count(n)) omni_step_px = std::min(omni_step_px, (detected_px[n] - corner.pixel).norm());
      small_square = !(omni_step_px >= min_checker_step_px);
    }
    if (small_square) {
      // kept as detected (below)
    } else if (!guess) {
      std::vector<Eigen::Vector2d> neighbours;
      for (int n : neighbour_ids)
        if (by_id.count(n)) neighbours.push_back(by_id[n]);
      moved = RefineInImage(target, grey, corner.pixel, neighbours, /*by_edges=*/false, &refined);
    } else if (rays.count(corner.id)) {
      const auto& [origin, direction] = rays[corner.id];
      // Patch focal length: kMagnification x the omni image's px per rad around this ray,
      // the larger of the two directions so neither is undersampled.
      const Eigen::Matrix3d frame = ViewFrame(direction, -guess->cache().camera_from_mirror_rotation.col(2));
      double omni_px_per_rad = 0.0;
      for (int axis = 0; axis < 2; ++axis) {
        Eigen::Vector2d offset_pixel;
        const double step_rad = 1e-3;
        if (guess->Project(origin + VirtualView::kFarMm * (direction + step_rad * frame.col(axis)).normalized(), &offset_pixel) ==
            ProjectionStatus::kOk)
          omni_px_per_rad = std::max(omni_px_per_rad, (offset_pixel - corner.pixel).norm() / step_rad);
      }
      // The patch shows the sphere through the board's corner (its depth from the angle a
      // known side subtends; tilt only shortens it, so the smallest estimate). At infinity
      // instead, the board's edges bent by the missing single viewpoint and straight-edge
      // fits missed corners by up to ~0.01 px, radius-dependent: on renders the mirror's
      // size absorbed it (A 4 std off with the true sensor as the guess; 0.0 std here).
      double depth_mm = HUGE_VAL;
      for (int n : neighbour_ids)
        if (rays.count(n) && board_mm.count(n) && board_mm.count(corner.id)) {
          const double angle_rad = std::acos(std::clamp(direction.dot(rays[n].second), -1.0, 1.0));
          if (angle_rad > 0.0) depth_mm = std::min(depth_mm, (board_mm[n] - board_mm[corner.id]).norm() / angle_rad);
        }
      if (!std::isfinite(depth_mm)) depth_mm = VirtualView::kFarMm;
      // Neighbours as the patch sees them: their points at that depth, from this ray's
      // origin (near the rim the rays' origins are mm apart).
      std::vector<Eigen::Vector2d> neighbours;  // in patch px from the patch centre, per unit focal length
      double distance = HUGE_VAL;
      for (int n : neighbour_ids)
        if (rays.count(n)) {
          const Eigen::Vector3d v = frame.transpose() * (rays[n].first + depth_mm * rays[n].second - origin);
          if (v.z() <= 0.0) continue;
          neighbours.emplace_back(v.x() / v.z(), v.y() / v.z());
          distance = std::min(distance, neighbours.back().norm());
        }
      // Small corners are magnified further, so that the neighbour sits kMinNeighbourPx
      // away in the patch and the edge profiles get enough samples.
      const double focal = std::max(kMagnification * omni_px_per_rad, kMinNeighbourPx / distance);
      distance *= focal;
      for (Eigen::Vector2d& n : neighbours) n *= focal;
      // Bounded: a corner whose neighbours sit absurdly far is not refined.
      if (omni_px_per_rad > 0.0 && std::isfinite(distance) && distance < 2000.0) {
        const int half_size = static_cast<int>(std::ceil(ReachOf(target, corner_by_edges ? CheckerRefinement::kEdges : checker_refinement) * distance)) + 4;
        const VirtualView patch(*guess, frame, origin, focal, 2 * half_size + 1, 2 * half_size + 1, depth_mm);
        const cv::Mat image = patch.Resample(grey, cv::INTER_CUBIC);
        const Eigen::Vector2d centre(half_size, half_size);
        for (Eigen::Vector2d& n : neighbours) n += centre;
        Eigen::Vector2d refined_patch;
        // Junctions by their edges only clear of the rim (their profiles reach a square
        // out); else their squares are fitted whole with the rim modelled (below).
        const bool readable = !(corner_by_edges && target.type() == CalibrationTarget::Type::kCheckerboard) ||
                              ClearOfRim(patch, centre, distance);
        moved = readable && RefineInImage(target, image, centre, neighbours, corner_by_edges, &refined_patch) &&
                patch.ToOmni(refined_patch, &refined);
      }
    }
    // A junction the edge profiles cannot read (the rim cuts its outer side, a square
    // squashed to a few px): its squares fitted whole (calib/checker_junction_fit.h).
    if (!moved && corner_by_edges && target.type() == CalibrationTarget::Type::kCheckerboard)
      moved = FitCheckerJunction(target, grey, *guess, warp, corner.id, corner.pixel, detected_px, &refined);
    // A prediction stands only where the edges show a junction (a window method such as
    // cornerSubPix settles on anything with a gradient).
    if (corner.predicted && !(moved && corner_by_edges)) continue;
    if (moved) {
      corner.pixel = refined;
      ++local.refined;
    } else if (guess && target.type() == CalibrationTarget::Type::kAprilGrid) {
      corner.unrefined = true;
      ++local.unrefined;
    } else {
      ++local.kept;
    }
    out.corners.push_back(corner);
  }
  // Aprilgrid tags whose four corners were found: the whole tag's pattern fitted to its
  // pixels (calib/tag_template_fit.h) from where the edge profiles (or the detector) put
  // them. A fit whose residual is far above the image's typical one settled in another
  // minimum (the bits one column over): those tags keep the corners above, as do all of an
  // image with under 3 fitted tags. A tag with predicted corners (cut by the rim:
  // calib/checkerboard_completion.h) is fitted across the rim, and those of its corners
  // the mirror shows are kept; a prediction without such a fit is dropped.
  std::set<size_t> confirmed;  // predicted corners a tag's fit placed
  if (guess && fit_whole_tags && target.type() == CalibrationTarget::Type::kAprilGrid) {
    std::map<int, std::array<int, 4>> tags;  // tag id -> index in out.corners per k
    for (size_t i = 0; i < out.corners.size(); ++i) {
      if (out.corners[i].id < 0) continue;  // not a tag's (the fit would find no such tag)
      auto entry = tags.try_emplace(out.corners[i].id / 4, std::array<int, 4>{-1, -1, -1, -1}).first;
      entry->second[out.corners[i].id % 4] = static_cast<int>(i);
    }
    struct Fitted {
      std::array<int, 4> index;
      TagTemplateFit fit;
      bool across_rim;
    };
    std::vector<Fitted> fits;
    for (const auto& [tag, index] : tags) {
      if (std::count(index.begin(), index.end(), -1) > 0) continue;
      std::array<Eigen::Vector2d, 4> start;
      // A detector's corner (its edge profiles failed) may move farther: at the rim they
      // sat 2.3-2.7 px from the fitted corners, over half a cell (1.9-2.2 px), and whole
      // tags were refused (realistic seeds: used 98.35 -> 98.57 % at 0.75 of a cell); on
      // squashed tags by the rim they sat 0.8-1.1 cells off where the fits were within
      // 0.01-0.27 px of the truth (1.25 cells: 23 more tags' corners over 6 seeds, 4 of
      // them cut; a fit one bit column over shows in its residual, checked below).
      std::array<double, 4> max_move_cells;
      bool across_rim = false;
      for (int k = 0; k < 4; ++k) {
        start[k] = out.corners[index[k]].pixel;
        across_rim = across_rim || out.corners[index[k]].predicted;
        max_move_cells[k] = out.corners[index[k]].unrefined ? kDetectorCornerMaxMoveCells : kRefinedCornerMaxMoveCells;
      }
      // A found tag with a corner at the rim (which the plain fit keeps clear of) is fitted
      // across it as well.
      TagTemplateFit fit;
      if (!across_rim && !FitTagTemplate(target, grey, *guess, warp, tag, start, &fit, false, max_move_cells)) across_rim = true;
      if (!across_rim || FitTagTemplate(target, grey, *guess, warp, tag, start, &fit, true, max_move_cells))
        fits.push_back({index, fit, across_rim});
    }
    // The median needs a few fits to say what is typical (the complete tags'): with fewer,
    // none is trusted.
    std::vector<double> relative;
    for (const Fitted& f : fits)
      if (!f.across_rim) relative.push_back(f.fit.rms_grey / f.fit.contrast);
    if (relative.size() >= 3) {
      std::nth_element(relative.begin(), relative.begin() + relative.size() / 2, relative.end());
      const double typical = relative[relative.size() / 2];
      for (const Fitted& f : fits) {
        if (f.fit.rms_grey / f.fit.contrast > 2.5 * typical) continue;
        for (int k = 0; k < 4; ++k) {
          if (!f.fit.on_mirror[k]) continue;
          CornerObservation& corner = out.corners[f.index[k]];
          corner.pixel = f.fit.corners_px[k];
          if (corner.predicted) confirmed.insert(f.index[k]), ++local.refined;
          if (corner.unrefined) corner.unrefined = false, --local.unrefined, ++local.refined;
        }
      }
    }
  }
  if (target.type() == CalibrationTarget::Type::kAprilGrid) {
    ImageDetections kept = out;
    kept.corners.clear();
    for (size_t i = 0; i < out.corners.size(); ++i)
      if (!out.corners[i].predicted || confirmed.count(i)) kept.corners.push_back(out.corners[i]);
    out = kept;
  }
  if (stats) *stats = local;
  return out;
}

}  // namespace omnical
