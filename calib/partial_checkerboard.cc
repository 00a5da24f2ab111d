#include "calib/partial_checkerboard.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <utility>

#include "calib/bilinear.h"
#include "calib/checkerboard_candidates.h"

namespace omnical {
namespace {

using Index = std::pair<int, int>;  // (row down, col) in the found part's own numbering
using Grid = std::map<Index, Eigen::Vector2d>;

// One step beyond `from` along direction (dr, dc), extrapolated from the corners behind it
// (quadratic along the line where three are known: the grid bends in an omni image); false
// where the line has only one known corner.
bool Predict(const Grid& grid, Index from, int dr, int dc, Eigen::Vector2d* predicted) {
  const auto behind = grid.find({from.first - dr, from.second - dc});
  if (behind == grid.end()) return false;
  const Eigen::Vector2d& p1 = grid.at(from);
  const auto further = grid.find({from.first - 2 * dr, from.second - 2 * dc});
  *predicted = further != grid.end() ? Eigen::Vector2d(3.0 * p1 - 3.0 * behind->second + further->second)
                                     : Eigen::Vector2d(2.0 * p1 - behind->second);
  return true;
}

// The grid step across direction (dr, dc) at a corner, from a known neighbour on either
// side; zero when it has none.
Eigen::Vector2d StepAcross(const Grid& grid, Index at, int dr, int dc) {
  const Eigen::Vector2d& p = grid.at(at);
  if (const auto next = grid.find({at.first + dc, at.second + dr}); next != grid.end()) return next->second - p;
  if (const auto previous = grid.find({at.first - dc, at.second - dr}); previous != grid.end()) return p - previous->second;
  return Eigen::Vector2d::Zero();
}

// The rows and columns the grid's corners span.
struct Extent {
  int min_row = INT32_MAX, max_row = INT32_MIN, min_col = INT32_MAX, max_col = INT32_MIN;
  int rows() const { return max_row - min_row + 1; }
  int cols() const { return max_col - min_col + 1; }
};
Extent ExtentOf(const Grid& grid) {
  Extent e;
  for (const auto& [index, pixel] : grid) {
    e.min_row = std::min(e.min_row, index.first), e.max_row = std::max(e.max_row, index.first);
    e.min_col = std::min(e.min_col, index.second), e.max_col = std::max(e.max_col, index.second);
  }
  return e;
}

// Grows the part corner by corner (see the header); false when it outgrows `longest`
// corners along an axis (a pattern larger than the board).
bool Grow(const cv::Mat& grey, double threshold, int longest, Grid* grid) {
  std::set<Index> refused;
  constexpr std::array<std::array<int, 2>, 4> kDirections = {{{1, 0}, {-1, 0}, {0, 1}, {0, -1}}};
  for (bool grew = true; grew;) {
    grew = false;
    std::vector<Index> known;
    for (const auto& [index, pixel] : *grid) known.push_back(index);
    for (const Index& at : known)
      for (const auto& [dr, dc] : kDirections) {
        const Index next{at.first + dr, at.second + dc};
        if (grid->count(next) || refused.count(next)) continue;
        Eigen::Vector2d predicted;
        const Eigen::Vector2d across = StepAcross(*grid, at, dr, dc);
        if (!Predict(*grid, at, dr, dc, &predicted) || across.isZero()) continue;
        const Eigen::Vector2d along = predicted - grid->at(at);
        const double step_px = std::min(along.norm(), across.norm());
        Eigen::Vector2d refined = predicted;
        if (!(XJunctionScore(grey, predicted, along, across) > threshold) || !PullOntoJunction(grey, step_px, &refined) ||
            !(XJunctionScore(grey, refined, along, across) > threshold)) {
          refused.insert(next);
          continue;
        }
        (*grid)[next] = refined;
        grew = true;
      }
    if (const Extent e = ExtentOf(*grid); e.rows() > longest || e.cols() > longest) return false;
  }
  return true;
}

// Whether at least three of the part's four sides show the board's white margin: a point
// one step beyond a corner on that side that is no X-junction and has paper further out
// (brighter than the mean of the part's squares: the midpoint of ink and paper). Growth
// stops at a margin, but also at the rim, a dark edge or the image's edge: a patch of a
// larger pattern (tiles) cut there to the board's size shows no paper; a board whose one
// side lies beyond the rim (realistic render rim0) shows it on three.
bool MarginOnThreeSides(const cv::Mat& grey, double threshold, const Grid& grid) {
  double square_sum = 0.0;
  int squares = 0;
  for (const auto& [index, pixel] : grid)
    if (const auto opposite = grid.find({index.first + 1, index.second + 1}); opposite != grid.end()) {
      const Eigen::Vector2d centre = 0.5 * (pixel + opposite->second);
      if (const double value = Bilinear<uchar>(grey, centre.x(), centre.y()); std::isfinite(value)) square_sum += value, ++squares;
    }
  if (squares == 0) return false;
  const double ink_paper_midpoint = square_sum / squares;
  const Extent e = ExtentOf(grid);
  struct Side {
    int dr, dc;
  };
  int sides_with_margin = 0;
  for (const Side side : {Side{-1, 0}, Side{1, 0}, Side{0, -1}, Side{0, 1}}) {
    bool margin_seen = false;
    for (const auto& [index, pixel] : grid) {
      const bool on_side = (side.dr < 0 && index.first == e.min_row) || (side.dr > 0 && index.first == e.max_row) ||
                           (side.dc < 0 && index.second == e.min_col) || (side.dc > 0 && index.second == e.max_col);
      Eigen::Vector2d beyond;
      const Eigen::Vector2d across = StepAcross(grid, index, side.dr, side.dc);
      if (!on_side || across.isZero() || !Predict(grid, index, side.dr, side.dc, &beyond)) continue;
      const double score = XJunctionScore(grey, beyond, beyond - pixel, across);
      if (!std::isfinite(score) || score > threshold) continue;
      // Paper half a step out, or a quarter step out beside both outer squares (a narrow or
      // shaded margin shows paper only close to the print: Mei's board at 640 px by the inner
      // radius read 112-144 half a step out on two sides against a midpoint of 154, and 182
      // and 171 a quarter step out). Both, because beyond a tile patch's last junctions the
      // next squares alternate ink and paper along the side; a margin runs along it.
      const auto paper_at = [&](double out, double along_side) {
        const Eigen::Vector2d at = beyond + out * (beyond - pixel) + along_side * across;
        return Bilinear<uchar>(grey, at.x(), at.y()) > ink_paper_midpoint;
      };
      if (paper_at(0.5, 0.0) || (paper_at(0.25, -0.5) && paper_at(0.25, 0.5))) margin_seen = true;
    }
    sides_with_margin += margin_seen;
  }
  return sides_with_margin >= 3;
}

}  // namespace

std::optional<PartialCheckerboard> FindPartialCheckerboard(const cv::Mat& grey, cv::Size pattern,
                                                           double junction_contrast_fraction) {
  CV_Assert(grey.type() == CV_8UC1);
  const cv::Size minimum(std::min(4, pattern.width), std::min(4, pattern.height));
  std::vector<cv::Point2f> found;
  cv::Mat meta;
  const uint64_t caller_rng = cv::theRNG().state;  // see FindCheckerboardCandidates
  cv::theRNG().state = cv::RNG().state;
  const bool ok = cv::findChessboardCornersSB(grey, minimum, found,
                                              cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_ACCURACY | cv::CALIB_CB_LARGER, meta);
  cv::theRNG().state = caller_rng;
  if (!ok || meta.empty() || static_cast<int>(found.size()) != meta.rows * meta.cols) return std::nullopt;
  CheckerGrid part;
  part.rows = meta.rows;
  part.cols = meta.cols;
  Grid grid;
  for (int i = 0; i < static_cast<int>(found.size()); ++i) {
    part.corners_px.emplace_back(found[i].x, found[i].y);
    grid[{i / part.cols, i % part.cols}] = part.corners_px.back();
  }
  // With CALIB_CB_LARGER the order can come transposed (measured on a flat print: rows of
  // the meta array running down the image's columns), a reflection of the numbering: made
  // right-handed as the complete search's (column step x row step > 0, image y down).
  const Eigen::Vector2d col_step = part.at(0, 1) - part.at(0, 0), row_step = part.at(1, 0) - part.at(0, 0);
  if (col_step.x() * row_step.y() - col_step.y() * row_step.x() < 0.0) {
    Grid transposed;
    for (const auto& [index, pixel] : grid) transposed[{index.second, index.first}] = pixel;
    grid = std::move(transposed);
  }
  const double threshold = junction_contrast_fraction * GridContrast(grey, part);
  if (!(threshold > 0.0) || !Grow(grey, threshold, std::max(pattern.width, pattern.height), &grid)) return std::nullopt;

  const Extent e = ExtentOf(grid);
  const int rows = e.rows(), cols = e.cols(), min_row = e.min_row, max_row = e.max_row, min_col = e.min_col;
  const bool fits_upright = rows <= pattern.height && cols <= pattern.width;
  const bool fits_turned = rows <= pattern.width && cols <= pattern.height;
  if (!fits_upright && !fits_turned) return std::nullopt;  // larger than the board
  const bool spans_upright = rows == pattern.height && cols == pattern.width;
  const bool spans_turned = rows == pattern.width && cols == pattern.height;
  PartialCheckerboard out;
  out.placed = (spans_upright || spans_turned) && MarginOnThreeSides(grey, threshold, grid);
  if (out.placed && !spans_upright) {
    // Turned a quarter: (row, col) -> (col, last row - row), a rotation of the numbering
    // (the image's handedness kept).
    for (const auto& [index, pixel] : grid) out.corners.push_back({index.second - min_col, max_row - index.first, pixel});
  } else {
    for (const auto& [index, pixel] : grid) out.corners.push_back({index.first - min_row, index.second - min_col, pixel});
  }
  std::sort(out.corners.begin(), out.corners.end(), [](const BoardCorner& a, const BoardCorner& b) {
    return std::make_pair(a.row_down, a.col) < std::make_pair(b.row_down, b.col);
  });
  return out;
}

}  // namespace omnical
