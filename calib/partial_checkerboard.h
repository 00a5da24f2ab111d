// A checkerboard only partly visible: cut by the mirror's rim, or seen at a grazing angle
// where a corner or two blur away. findChessboardCornersSB finds complete boards only;
// with CALIB_CB_LARGER and a 4 x 4 minimum it returns any part of a grid it can order,
// which is then grown corner by corner: one step beyond a known corner along a grid line
// (quadratic along the line where three are known), kept when the image has an X-junction
// there (XJunctionScore above a fraction of the part's own contrast) and cornerSubPix pulls
// the point onto it within a quarter of a step. Growth stops at the board's white margin,
// at the rim and at the image's edge.
//
// A part is placed on the board only when its corners span the board's full extent along
// both axes and three of its four sides show the board's white margin somewhere (a point
// one step beyond, no X-junction, with paper further out; the fourth may lie beyond the
// rim): then each corner's row and column on the board follow (up to the 180 deg turn
// calib/detect.h resolves from the print). A part that spans less could sit anywhere
// along the short axis (returned, not placed: aim a view at it); one larger than the
// board, or cut to its size by the rim or the image's edge with paper seen on fewer
// sides, is a patch of a larger pattern (tiles).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <optional>
#include <vector>

namespace omnical {

struct BoardCorner {
  int row_down = 0, col = 0;  // on the board as seen, rows downwards: findChessboardCornersSB's order
  Eigen::Vector2d pixel;
};

struct PartialCheckerboard {
  // placed: the corners span the board, row_down and col are the board's. Not placed: a
  // part cut by the image's edge (row_down and col its own, from 0) — aim another view at
  // it and search again.
  bool placed = false;
  std::vector<BoardCorner> corners;
};

// The visible corners of a board of `pattern` inner corners (cols x rows) in an image of
// normal handedness (a perspective view, or an omni image flipped), or nullopt when no
// part is found or the part outgrows the board. Deterministic: cv::theRNG() is reset for
// the search and restored.
std::optional<PartialCheckerboard> FindPartialCheckerboard(const cv::Mat& grey, cv::Size pattern,
                                                           double junction_contrast_fraction = 0.3);

}  // namespace omnical
