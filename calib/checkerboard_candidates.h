// Every checkerboard-like grid in an image, each accepted or refused with a reason. A
// room's checked floor, tiles or a window's bars reflected in the mirror can look like the
// board to OpenCV's findChessboardCornersSB, which returns the first grid it completes:
// the search is repeated with each found grid's region masked out, and a grid that is a
// window into a larger checker pattern is refused. A printed board has a white margin, so
// one grid step beyond its outer inner corners lies the paper (or the board's edge, or
// the dark rim): no X-junction. Beyond a patch of tiles lie more tiles: X-junctions.
//
// Pixel-centre coordinates of the image given, as everywhere (a mirror image is searched
// flipped, see CheckerboardCandidateOptions::mirrored).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace omnical {

// A grid of inner corners as findChessboardCornersSB returns it: row-major, rows x cols.
struct CheckerGrid {
  int rows = 0, cols = 0;
  std::vector<Eigen::Vector2d> corners_px;
  const Eigen::Vector2d& at(int row, int col) const { return corners_px[row * cols + col]; }
};

// How strongly the image has an X-junction (a checker corner) at a point, given the two
// local grid steps through it: the means of the four quadrants between the grid lines
// (3 x 3 bilinear samples at 0.15-0.35 of each step from the point: clear of blurred grid
// lines, and tolerant of a point predicted a fifth of a step off), and
//   score = max(min(q0, q2) - max(q1, q3), min(q1, q3) - max(q0, q2))   (quadrants cyclic)
// in grey levels: > 0 only when opposite quadrants are alike and both darker or both
// lighter than the other pair. An L or T corner (a board's outer squares against its white
// margin) scores <= 0. NaN where a sample leaves the image (not testable).
double XJunctionScore(const cv::Mat& grey, const Eigen::Vector2d& point_px, const Eigen::Vector2d& step_a_px,
                      const Eigen::Vector2d& step_b_px);

// A predicted X-junction pulled onto the image's junction by cornerSubPix (half window 0.3
// of the grid step `step_px`, so it stays inside the point's four squares): false when the
// window leaves the image or the point moves more than a quarter step (it found another
// junction, or none).
bool PullOntoJunction(const cv::Mat& grey, double step_px, Eigen::Vector2d* point);

enum class GridEdge { kTop, kBottom, kLeft, kRight };  // first row, last row, first column, last column
const char* GridEdgeName(GridEdge edge);               // "first row", ..., "last column"

struct CheckerboardCandidateOptions {
  bool mirrored = true;    // search the image flipped left-right (a mirror's), report in the image's own pixels
  int max_candidates = 3;  // findChessboardCornersSB searches (EXHAUSTIVE | ACCURACY) per image
  // At 1040 px a search that finds a grid takes ~0.6-1 s, one that finds nothing ~1.5-3 s
  // (measured): stopping at the first accepted grid keeps an image without decoys at one
  // search, as before. false: every candidate up to max_candidates (about 2x the time).
  bool stop_at_first_accepted = true;
  // An edge continues when at least this fraction of the points one step beyond it are
  // X-junctions: a tile pattern seen past an occluder, or partly beyond the mirror, still
  // shows most; a board's margin shows none.
  double continuing_fraction = 0.5;
  // An X-junction: score above this fraction of the grid's own square contrast (printed
  // ink against paper, or the tiles' two levels as seen at its corners).
  double junction_contrast_fraction = 0.3;
  bool Check(std::string* error) const;  // false with the reason for an invalid field
};

// Per edge of a grid, how many of the points one step beyond it were X-junctions (of how
// many could be tested: inside the image).
struct GridContinuation {
  GridEdge edge;
  std::string facing;  // the image side the edge faces: "left", "right", "top" or "bottom"
  int junctions = 0, tested = 0;
};

// The grid's square contrast (median over its squares of |light - dark| near corners, grey
// levels) and, per edge, the X-junctions one step beyond it (corners extrapolated
// quadratically along the grid, which follows a mirror's curvature).
double GridContrast(const cv::Mat& grey, const CheckerGrid& grid);
std::vector<GridContinuation> GridContinuations(const cv::Mat& grey, const CheckerGrid& grid,
                                                const CheckerboardCandidateOptions& options);

struct CheckerboardCandidate {
  CheckerGrid grid;       // as found in the searched (flipped, if mirrored) image, in the given image's pixels
  double contrast = 0.0;  // grey levels (GridContrast)
  bool accepted = false;
  std::string refusal;  // why it was refused: "a patch of a larger checker pattern (...)"
};

// A found grid's corners checked against the image: findChessboardCornersSB can return
// the outer corners of a strongly sheared board on a square's edge instead of its
// junction (the realistic render's real001 near the rim: 2.4-12.9 px off). A point is a
// junction where XJunctionScore exceeds `threshold` and, on grid steps of 20 px and more,
// cornerSubPix (PullOntoJunction) started on it settles within max(1.5 px, 0.05 step) and,
// started a tenth of a step away along either grid line, comes back within max(0.5 px,
// 0.03 step) (on a straight edge it only moves across the edge; a start too near the
// image's edge is skipped); the score is then taken where it settled. Steps come from the
// corner's neighbours that passed, not from the corner itself (where no two did: the found
// grid's), and the step that sizes cornerSubPix's window is the distance to the nearest
// other junction (a sheared grid's short diagonal too). Two passes:
// 1. each corner on its own, the corner kept where found if it is a junction;
// 2. row by row, one that failed: kept if it passes with the steps of its neighbours that
//    passed (or were re-placed before it); else put at the first junction a prediction
//    from them pulls onto (one-sided quadratic from three towards the board's inside
//    first, then the midpoint of two on a line through it); else where cornerSubPix
//    settles from it, if that is a junction; else dropped.
// A corner that cannot be scored (its samples leave the image) is kept as found.
struct CheckedGrid {
  std::vector<Eigen::Vector2d> corners_px;  // the grid's, re-placed ones moved
  std::vector<bool> kept;                   // per corner: false where dropped
  int replaced = 0, dropped = 0;
};
CheckedGrid CheckGridJunctions(const cv::Mat& grey, const CheckerGrid& grid, double threshold);

// Up to options.max_candidates grids of `pattern` (inner corners, cols x rows) found by
// findChessboardCornersSB (EXHAUSTIVE | ACCURACY), each found grid's region (the grid
// extended one step on every side; a refused pattern followed outwards first) filled with
// its mean grey before the next search, in the order found, until a search finds nothing
// (or, by default, a grid is accepted). Each is checked (GridContinuations) and refused
// when any edge continues. Deterministic: the same image gives the same candidates.
// Throws std::invalid_argument for invalid options or a pattern under 2 x 2.
std::vector<CheckerboardCandidate> FindCheckerboardCandidates(const cv::Mat& grey, cv::Size pattern,
                                                              const CheckerboardCandidateOptions& options = {});

}  // namespace omnical
