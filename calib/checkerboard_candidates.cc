#include "calib/checkerboard_candidates.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <stdexcept>

#include "calib/bilinear.h"

namespace omnical {
namespace {

// Growth of a refused pattern before it is masked: tiles reflected around the image
// centre can span ~50 steps; past that the extrapolation is not worth following.
constexpr int kMaxGrowthSteps = 40;

// The lines of a grid parallel to an edge, the edge first, going inwards.
std::vector<std::vector<Eigen::Vector2d>> LinesFrom(const CheckerGrid& grid, GridEdge edge) {
  const bool by_row = edge == GridEdge::kTop || edge == GridEdge::kBottom;
  const int count = by_row ? grid.rows : grid.cols, length = by_row ? grid.cols : grid.rows;
  std::vector<std::vector<Eigen::Vector2d>> lines(count);
  for (int k = 0; k < count; ++k) {
    const int line = (edge == GridEdge::kTop || edge == GridEdge::kLeft) ? k : count - 1 - k;
    for (int i = 0; i < length; ++i) lines[k].push_back(by_row ? grid.at(line, i) : grid.at(i, line));
  }
  return lines;
}

// The points one grid step beyond an edge: quadratic along each grid line across the edge
// (a mirror bends the grid; a straight-line guess drifts by a few px per step near the rim).
std::vector<Eigen::Vector2d> Beyond(const std::vector<std::vector<Eigen::Vector2d>>& lines) {
  std::vector<Eigen::Vector2d> beyond(lines[0].size());
  for (size_t i = 0; i < beyond.size(); ++i)
    beyond[i] = lines.size() >= 3 ? Eigen::Vector2d(3.0 * lines[0][i] - 3.0 * lines[1][i] + lines[2][i])
                                  : Eigen::Vector2d(2.0 * lines[0][i] - lines[1][i]);
  return beyond;
}

// The step along a line at index i (central where it can be).
Eigen::Vector2d AlongStep(const std::vector<Eigen::Vector2d>& line, size_t i) {
  if (line.size() < 2) return Eigen::Vector2d::Zero();
  if (i == 0) return line[1] - line[0];
  if (i + 1 == line.size()) return line[i] - line[i - 1];
  return 0.5 * (line[i + 1] - line[i - 1]);
}

// The grid with one more line beyond `edge`.
CheckerGrid Extended(const CheckerGrid& grid, GridEdge edge, const std::vector<Eigen::Vector2d>& beyond) {
  CheckerGrid out;
  const bool by_row = edge == GridEdge::kTop || edge == GridEdge::kBottom;
  const bool before = edge == GridEdge::kTop || edge == GridEdge::kLeft;
  out.rows = grid.rows + (by_row ? 1 : 0);
  out.cols = grid.cols + (by_row ? 0 : 1);
  out.corners_px.resize(out.rows * out.cols);
  for (int r = 0; r < out.rows; ++r)
    for (int c = 0; c < out.cols; ++c) {
      const int r0 = by_row && before ? r - 1 : r, c0 = !by_row && before ? c - 1 : c;
      const bool is_new = by_row ? (before ? r == 0 : r == out.rows - 1) : (before ? c == 0 : c == out.cols - 1);
      out.corners_px[r * out.cols + c] = is_new ? beyond[by_row ? c : r] : grid.at(r0, c0);
    }
  return out;
}

// The image side each edge faces (kTop, kBottom, kLeft, kRight order), distinct names: of
// the two pairs of opposite edges, the one whose outward steps are more horizontal is
// "left"/"right", the other "top"/"bottom" (image y runs down).
std::array<std::string, 4> FacingNames(const CheckerGrid& grid) {
  std::array<Eigen::Vector2d, 4> outward;
  int k = 0;
  for (GridEdge edge : {GridEdge::kTop, GridEdge::kBottom, GridEdge::kLeft, GridEdge::kRight}) {
    const auto lines = LinesFrom(grid, edge);
    outward[k] = Eigen::Vector2d::Zero();
    for (size_t i = 0; i < lines[0].size(); ++i) outward[k] += (lines[0][i] - lines[1][i]).normalized();
    ++k;
  }
  std::array<std::string, 4> names;
  const Eigen::Vector2d rows = outward[1] - outward[0], columns = outward[3] - outward[2];
  const bool rows_horizontal = std::abs(rows.x()) / rows.norm() > std::abs(columns.x()) / columns.norm();
  const int h = rows_horizontal ? 0 : 2, v = rows_horizontal ? 2 : 0;  // first edge of each pair
  const bool h_first_left = outward[h].x() < outward[h + 1].x(), v_first_top = outward[v].y() < outward[v + 1].y();
  names[h] = h_first_left ? "left" : "right";
  names[h + 1] = h_first_left ? "right" : "left";
  names[v] = v_first_top ? "top" : "bottom";
  names[v + 1] = v_first_top ? "bottom" : "top";
  return names;
}

// Per point beyond an edge: is it an X-junction (-1: not testable).
std::vector<int> JunctionsBeyond(const cv::Mat& grey, const std::vector<std::vector<Eigen::Vector2d>>& lines,
                                 const std::vector<Eigen::Vector2d>& beyond, double threshold) {
  std::vector<int> out(beyond.size());
  for (size_t i = 0; i < beyond.size(); ++i) {
    const Eigen::Vector2d across = beyond[i] - lines[0][i], along = AlongStep(beyond, i);
    const double score = XJunctionScore(grey, beyond[i], across, along);
    out[i] = std::isnan(score) ? -1 : score > threshold;
  }
  return out;
}

// Two tested points at least: one junction alone may be a tile's corner by chance.
bool Continues(const GridContinuation& edge, double fraction) {
  return edge.tested >= 2 && edge.junctions >= fraction * edge.tested;
}

double Mean(const std::array<double, 9>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return sum / v.size();
}

// Per edge, the X-junctions one step beyond it scoring above `threshold`.
std::vector<GridContinuation> Continuations(const cv::Mat& grey, const CheckerGrid& grid, double threshold) {
  const std::array<std::string, 4> facing = FacingNames(grid);
  std::vector<GridContinuation> out;
  for (GridEdge edge : {GridEdge::kTop, GridEdge::kBottom, GridEdge::kLeft, GridEdge::kRight}) {
    const auto lines = LinesFrom(grid, edge);
    GridContinuation continuation{edge, facing[static_cast<int>(edge)]};
    for (int j : JunctionsBeyond(grey, lines, Beyond(lines), threshold))
      if (j >= 0) ++continuation.tested, continuation.junctions += j;
    out.push_back(continuation);
  }
  return out;
}

// Follows a refused pattern outwards while its edges keep showing X-junctions, each new
// line pulled onto the junctions by cornerSubPix, so the whole pattern is masked at once
// rather than found again patch by patch.
CheckerGrid GrowPattern(const cv::Mat& grey, CheckerGrid grid, double threshold) {
  for (int step = 0; step < kMaxGrowthSteps; ++step) {
    bool grew = false;
    for (GridEdge edge : {GridEdge::kTop, GridEdge::kBottom, GridEdge::kLeft, GridEdge::kRight}) {
      const auto lines = LinesFrom(grid, edge);
      std::vector<Eigen::Vector2d> beyond = Beyond(lines);
      // Every point a junction, not just most: a line that runs partly off the pattern
      // (a room's corner, the board) would steer the next extrapolation off it.
      const std::vector<int> junctions = JunctionsBeyond(grey, lines, beyond, threshold);
      if (std::count(junctions.begin(), junctions.end(), 1) != static_cast<int>(junctions.size())) continue;
      double step_px = HUGE_VAL;
      for (size_t i = 0; i < beyond.size(); ++i) step_px = std::min(step_px, (beyond[i] - lines[0][i]).norm());
      // A point off the image: the pattern runs off it, and masking what is inside is enough.
      bool on_junctions = true;
      for (Eigen::Vector2d& p : beyond) on_junctions = on_junctions && PullOntoJunction(grey, step_px, &p);
      if (!on_junctions) continue;
      grid = Extended(grid, edge, beyond);
      grew = true;
    }
    if (!grew) break;
  }
  return grid;
}

// Fills the grid's cells, extended one step on every side and dilated by 2 px (the blurred
// edges), with their mean grey: the next search cannot complete a grid there, and no new
// strong edges are made inside.
void MaskGrid(const CheckerGrid& grid, cv::Mat* image) {
  CheckerGrid extended = grid;
  for (GridEdge edge : {GridEdge::kTop, GridEdge::kBottom, GridEdge::kLeft, GridEdge::kRight})
    extended = Extended(extended, edge, Beyond(LinesFrom(extended, edge)));
  cv::Mat mask = cv::Mat::zeros(image->size(), CV_8U);
  for (int r = 0; r + 1 < extended.rows; ++r)
    for (int c = 0; c + 1 < extended.cols; ++c) {
      std::array<cv::Point, 4> quad;
      const Eigen::Vector2d* cell[4] = {&extended.at(r, c), &extended.at(r, c + 1), &extended.at(r + 1, c + 1),
                                        &extended.at(r + 1, c)};
      for (int k = 0; k < 4; ++k) quad[k] = cv::Point(cvRound(cell[k]->x()), cvRound(cell[k]->y()));
      cv::fillConvexPoly(mask, quad.data(), 4, cv::Scalar(255));
    }
  cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
  image->setTo(cv::mean(*image, mask), mask);
}

// PullOntoJunction's cornerSubPix window: half its side, and whether it fits in the image
// around `start`.
int PullHalfWindow(double step_px) { return std::max(2, static_cast<int>(0.3 * step_px)); }
bool PullWindowFits(const cv::Mat& grey, double step_px, const Eigen::Vector2d& start) {
  const int half_window = PullHalfWindow(step_px);
  return start.x() >= half_window + 1 && start.y() >= half_window + 1 && start.x() < grey.cols - half_window - 2 &&
         start.y() < grey.rows - half_window - 2;
}

}  // namespace

bool PullOntoJunction(const cv::Mat& grey, double step_px, Eigen::Vector2d* point) {
  const int half_window = PullHalfWindow(step_px);
  const Eigen::Vector2d start = *point;
  if (!PullWindowFits(grey, step_px, start)) return false;
  std::vector<cv::Point2f> refined{cv::Point2f(static_cast<float>(start.x()), static_cast<float>(start.y()))};
  cv::cornerSubPix(grey, refined, cv::Size(half_window, half_window), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 20, 0.05));
  *point = Eigen::Vector2d(refined[0].x, refined[0].y);
  return (*point - start).norm() < 0.25 * step_px;
}

CheckedGrid CheckGridJunctions(const cv::Mat& grey, const CheckerGrid& grid, double threshold) {
  const int count = grid.rows * grid.cols;
  CheckerGrid working = grid;  // the corners as re-placed so far
  std::vector<bool> good(count, true), replaced(count, false), dropped(count, false);
  auto is_good = [&](int r, int c) {
    return r >= 0 && c >= 0 && r < grid.rows && c < grid.cols && good[r * grid.cols + c];
  };
  // The grid step through (r, c) along (dr, dc) from its neighbours that passed, never from
  // the corner itself (an end corner off its junction would shorten its own step).
  auto step_along = [&](int r, int c, int dr, int dc) -> Eigen::Vector2d {
    if (is_good(r - dr, c - dc) && is_good(r + dr, c + dc))
      return 0.5 * (working.at(r + dr, c + dc) - working.at(r - dr, c - dc));
    for (const int sign : {1, -1})
      if (is_good(r + sign * dr, c + sign * dc) && is_good(r + 2 * sign * dr, c + 2 * sign * dc))
        return sign * (working.at(r + 2 * sign * dr, c + 2 * sign * dc) - working.at(r + sign * dr, c + sign * dc));
    std::vector<Eigen::Vector2d> line;  // no two neighbours passed: the found grid's step (the corner's own too)
    for (int k = 0; k < (dr ? grid.rows : grid.cols); ++k) line.push_back(dr ? grid.at(k, c) : grid.at(r, k));
    return AlongStep(line, dr ? r : c);
  };
  auto score_at = [&](const Eigen::Vector2d& point, int r, int c) {
    return XJunctionScore(grey, point, step_along(r, c, 0, 1), step_along(r, c, 1, 0));
  };
  // The distance to the nearest other junction (on a sheared grid the short diagonal):
  // cornerSubPix's window (PullOntoJunction: 0.3 of it) then stays clear of other junctions.
  auto step_at = [&](int r, int c) {
    const Eigen::Vector2d a = step_along(r, c, 0, 1), b = step_along(r, c, 1, 0);
    return std::min({a.norm(), b.norm(), (a - b).norm(), (a + b).norm()});
  };
  // cornerSubPix started on a corner of the detector's settles within this of it (renders:
  // 0.1-0.9 px); started on a square's edge it travels 2.5-10 px. On steps under
  // kMinPullStepPx its window holds too few pixels to judge the detector by: on the real
  // Mei images (steps 8-36 px) it moved two small-square corners that fitted at 0.2 px by 1.5-2 px.
  auto tolerance_px = [](double step_px) { return std::max(1.5, 0.05 * step_px); };
  constexpr double kMinPullStepPx = 20.0;
  // A junction at `point` for corner (r, c): X-shaped there and, on steps >= kMinPullStepPx,
  // where cornerSubPix settles when started on it and again when started a tenth of a step
  // away along either grid line: on a straight edge it only moves across the edge, so starts
  // along it stay apart (an edge point passes the X test when the junction is within a
  // quarter step). Returns where cornerSubPix settled.
  auto junction_at = [&](Eigen::Vector2d point, int r, int c) -> std::optional<Eigen::Vector2d> {
    const double step_px = step_at(r, c);
    if (step_px >= kMinPullStepPx) {
      const Eigen::Vector2d start = point;
      if (!PullOntoJunction(grey, step_px, &point) || (point - start).norm() > tolerance_px(step_px))
        return std::nullopt;
      const double agree_px = std::max(0.5, 0.03 * step_px);
      for (const Eigen::Vector2d& along : {step_along(r, c, 0, 1), step_along(r, c, 1, 0)})
        for (const double sign : {1.0, -1.0}) {
          Eigen::Vector2d from = point + sign * 0.1 * step_px * along.normalized();
          // A start too near the image's edge for cornerSubPix's window is no evidence.
          if (!PullWindowFits(grey, step_px, from)) continue;
          if (!PullOntoJunction(grey, step_px, &from) || (from - point).norm() > agree_px) return std::nullopt;
        }
    }
    if (!(score_at(point, r, c) > threshold)) return std::nullopt;
    return point;
  };
  // Where the corner's neighbours that passed put it, pulled onto the image's junction:
  // one-sided (quadratic from three towards the board's inside) first, then midpoints of
  // two on a line through it (an edge row or column the detector misplaced as a whole
  // agrees with itself; the lines across it do not). The first that is a junction.
  auto predicted = [&](int r, int c) -> std::optional<Eigen::Vector2d> {
    std::vector<Eigen::Vector2d> guesses;
    for (const bool one_sided : {true, false})
      for (const auto& [dr, dc] : {std::pair<int, int>{0, 1}, {1, 0}}) {
        const bool both = is_good(r - dr, c - dc) && is_good(r + dr, c + dc);
        if (!one_sided && both) guesses.push_back(0.5 * (working.at(r - dr, c - dc) + working.at(r + dr, c + dc)));
        if (!one_sided || both) continue;
        for (const int sign : {1, -1}) {
          const int r1 = r + sign * dr, c1 = c + sign * dc, r2 = r + 2 * sign * dr, c2 = c + 2 * sign * dc,
                    r3 = r + 3 * sign * dr, c3 = c + 3 * sign * dc;
          if (is_good(r1, c1) && is_good(r2, c2) && is_good(r3, c3)) {
            guesses.push_back(3.0 * working.at(r1, c1) - 3.0 * working.at(r2, c2) + working.at(r3, c3));
            break;
          }
        }
      }
    const double step_px = step_at(r, c);
    for (Eigen::Vector2d guess : guesses)
      if (PullOntoJunction(grey, step_px, &guess))
        if (const std::optional<Eigen::Vector2d> junction = junction_at(guess, r, c)) return junction;
    return std::nullopt;
  };
  auto replace = [&](int r, int c, const Eigen::Vector2d& point) {
    working.corners_px[r * grid.cols + c] = point;
    replaced[r * grid.cols + c] = good[r * grid.cols + c] = true;
  };

  // 1. Each corner on its own (every other corner taken as found). Not testable (samples
  // off the image): kept as found.
  std::vector<bool> passed(count, true);
  for (int r = 0; r < grid.rows; ++r)
    for (int c = 0; c < grid.cols; ++c)
      if (!std::isnan(score_at(grid.at(r, c), r, c)))
        passed[r * grid.cols + c] = junction_at(grid.at(r, c), r, c).has_value();
  good = passed;
  // 2. The ones that failed, against their neighbours that passed (and those re-placed
  // before them): a corner that passes now (its steps were its own bad neighbours') stays;
  // else the junction a prediction pulls onto, or where cornerSubPix settles from the
  // corner; else dropped.
  for (int r = 0; r < grid.rows; ++r)
    for (int c = 0; c < grid.cols; ++c) {
      const int index = r * grid.cols + c;
      if (good[index]) continue;
      if (junction_at(grid.at(r, c), r, c)) {
        good[index] = true;
        continue;
      }
      if (const std::optional<Eigen::Vector2d> where = predicted(r, c)) {
        replace(r, c, *where);
        continue;
      }
      Eigen::Vector2d settled = grid.at(r, c);
      if (PullOntoJunction(grey, step_at(r, c), &settled)) {
        if (const std::optional<Eigen::Vector2d> junction = junction_at(settled, r, c)) {
          replace(r, c, *junction);
          continue;
        }
      }
      dropped[index] = true;
    }
  CheckedGrid out;
  out.corners_px = working.corners_px;
  for (int k = 0; k < count; ++k) {
    out.kept.push_back(!dropped[k]);
    out.replaced += replaced[k] ? 1 : 0;
    out.dropped += dropped[k] ? 1 : 0;
  }
  return out;
}

const char* GridEdgeName(GridEdge edge) {
  switch (edge) {
    case GridEdge::kTop:
      return "first row";
    case GridEdge::kBottom:
      return "last row";
    case GridEdge::kLeft:
      return "first column";
    case GridEdge::kRight:
      return "last column";
  }
  return "?";
}

double XJunctionScore(const cv::Mat& grey, const Eigen::Vector2d& point_px, const Eigen::Vector2d& step_a_px,
                      const Eigen::Vector2d& step_b_px) {
  CV_Assert(grey.type() == CV_8UC1);
  // Quadrant k lies at signs (sa, sb) = (+,+), (-,+), (-,-), (+,-): cyclic around the point.
  constexpr int kSigns[4][2] = {{1, 1}, {-1, 1}, {-1, -1}, {1, -1}};
  constexpr double kOffsets[3] = {0.15, 0.25, 0.35};  // fractions of a step: clear of the grid lines
  std::array<double, 4> quadrant;
  for (int k = 0; k < 4; ++k) {
    std::array<double, 9> samples;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const Eigen::Vector2d at =
            point_px + kSigns[k][0] * kOffsets[i] * step_a_px + kSigns[k][1] * kOffsets[j] * step_b_px;
        samples[3 * i + j] = Bilinear<uchar>(grey, at.x(), at.y());
        if (std::isnan(samples[3 * i + j])) return NAN;
      }
    quadrant[k] = Mean(samples);
  }
  return std::max(std::min(quadrant[0], quadrant[2]) - std::max(quadrant[1], quadrant[3]),
                  std::min(quadrant[1], quadrant[3]) - std::max(quadrant[0], quadrant[2]));
}

bool CheckerboardCandidateOptions::Check(std::string* error) const {
  if (max_candidates < 1) return *error = "max_candidates must be >= 1", false;
  if (!(continuing_fraction > 0.0 && continuing_fraction <= 1.0))
    return *error = "continuing_fraction must be in (0, 1]", false;
  if (!(junction_contrast_fraction > 0.0 && junction_contrast_fraction < 1.0))
    return *error = "junction_contrast_fraction must be in (0, 1)", false;
  return true;
}

double GridContrast(const cv::Mat& grey, const CheckerGrid& grid) {
  std::vector<double> scores;
  for (int r = 0; r < grid.rows; ++r) {
    std::vector<Eigen::Vector2d> row, column;
    for (int c = 0; c < grid.cols; ++c) row.push_back(grid.at(r, c));
    for (int c = 0; c < grid.cols; ++c) {
      column.clear();
      for (int k = 0; k < grid.rows; ++k) column.push_back(grid.at(k, c));
      const double score = XJunctionScore(grey, grid.at(r, c), AlongStep(row, c), AlongStep(column, r));
      if (!std::isnan(score)) scores.push_back(score);
    }
  }
  if (scores.empty()) return 0.0;
  std::nth_element(scores.begin(), scores.begin() + scores.size() / 2, scores.end());
  return scores[scores.size() / 2];
}

std::vector<GridContinuation> GridContinuations(const cv::Mat& grey, const CheckerGrid& grid,
                                                const CheckerboardCandidateOptions& options) {
  return Continuations(grey, grid, options.junction_contrast_fraction * GridContrast(grey, grid));
}

std::vector<CheckerboardCandidate> FindCheckerboardCandidates(const cv::Mat& grey, cv::Size pattern,
                                                              const CheckerboardCandidateOptions& options) {
  CV_Assert(grey.type() == CV_8UC1);
  if (std::string error; !options.Check(&error))
    throw std::invalid_argument("checkerboard candidate options: " + error);
  // Extrapolating across an edge needs a second line.
  if (pattern.width < 2 || pattern.height < 2)
    throw std::invalid_argument("checkerboard pattern under 2 x 2 inner corners");
  std::vector<CheckerboardCandidate> candidates;
  cv::Mat search;
  if (options.mirrored)
    cv::flip(grey, search, 1);
  else
    search = grey.clone();
  // The searched image's pixels <-> the given image's: a flip maps column x to cols - 1 - x.
  auto to_grey = [&](Eigen::Vector2d p) {
    if (options.mirrored) p.x() = grey.cols - 1 - p.x();
    return p;
  };
  for (int k = 0; k < options.max_candidates; ++k) {
    std::vector<cv::Point2f> found;
    // findChessboardCornersSB draws from the thread's cv::theRNG(): the same image gives
    // another grid, or none, after other detections ran in the thread. A fresh thread's
    // state for every search makes detection depend on the image alone; the caller's
    // state is put back.
    const uint64_t caller_rng = cv::theRNG().state;
    cv::theRNG().state = cv::RNG().state;
    const bool ok =
        cv::findChessboardCornersSB(search, pattern, found, cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_ACCURACY);
    cv::theRNG().state = caller_rng;
    if (!ok) break;
    CheckerboardCandidate candidate;
    candidate.grid.rows = pattern.height;
    candidate.grid.cols = pattern.width;
    for (const cv::Point2f& p : found) candidate.grid.corners_px.push_back(to_grey(Eigen::Vector2d(p.x, p.y)));
    // Measured on the image itself: the mask of earlier candidates must not change them.
    candidate.contrast = GridContrast(grey, candidate.grid);
    const double threshold = options.junction_contrast_fraction * candidate.contrast;
    std::vector<std::string> continuing;
    for (const GridContinuation& edge : Continuations(grey, candidate.grid, threshold))
      if (Continues(edge, options.continuing_fraction)) continuing.push_back(edge.facing);
    candidate.accepted = continuing.empty();
    CheckerGrid masked = candidate.grid;
    if (!candidate.accepted) {
      std::string where = continuing[0];
      for (size_t i = 1; i < continuing.size(); ++i)
        where += (i + 1 == continuing.size() ? " and " : ", ") + continuing[i];
      candidate.refusal = "a patch of a larger checker pattern (the grid continues past its " + where +
                          (continuing.size() > 1 ? " edges)" : " edge)");
      masked = GrowPattern(grey, candidate.grid, threshold);
    }
    for (Eigen::Vector2d& p : masked.corners_px) p = to_grey(p);  // the flip is its own inverse
    MaskGrid(masked, &search);
    const bool accepted = candidate.accepted;
    candidates.push_back(std::move(candidate));
    if (accepted && options.stop_at_first_accepted) break;
  }
  return candidates;
}

}  // namespace omnical
