// A per-pixel table of omni-image pixels (a remap table's, a virtual view's) filled from
// exact projections on a grid of nodes every `step_px` table pixels, interpolated between
// them with 4-point Lagrange cubics in both directions (error ~h^4). Each grid cell is
// checked at its centre against an exact projection; a cell that misses by more than
// kCellCheckTolerancePx, or touches a node without a pixel (field edges, the image
// border), is projected pixel by pixel. Measured against per-pixel tables on every
// misaligned test sensor (tests/remap_test.cc, and the VirtualView test in
// tests/detect_test.cc): below 0.01 px everywhere. Rows of nodes, cells and pixels spread
// over threads.
#pragma once

#include <Eigen/Core>

#include <functional>

namespace omnical {

// Nodes about this far apart: on the test sensors (rim ~480 px), 2 deg cells pass the
// check almost everywhere the field is smooth, 4 deg cells fail in ~10-50 % of the
// field, 8 deg in most of it (measured while writing tests/remap_test.cc).
constexpr double kNodeSpacingDeg = 2.0;

// A cell whose centre misses the exact pixel by more is projected pixel by pixel; a
// third of the 0.01 px the tables promise, because the centre is not always the worst
// point of a cell (the tests measure the whole tables).
constexpr double kCellCheckTolerancePx = 0.003;

// Table pixels per kNodeSpacingDeg for a table whose pixels subtend `pixel_rad` at its
// centre, clamped to [2, 64].
int NodeStepPx(double pixel_rad);

// Exact omni pixels of table points (columns: x, y in table pixels, which may lie
// outside the table by up to two steps); NaN where a point has none.
using GridTableProjector = std::function<Eigen::Matrix2Xd(const Eigen::Matrix2Xd& table_points)>;

struct GridTableFill {
  long valid_pixels = 0;
  long exact_pixels = 0;          // projected one by one (failed cells, field edges)
  double worst_cell_check_px = 0;
};

struct GridTableRequest {
  int width = 0, height = 0, step_px = 2, threads = 1;
  GridTableProjector project;
  // Whether an interpolated pixel is kept (e.g. inside the image); null: all are.
  std::function<bool(double x, double y)> keep;
  // Called after each table row (from any thread); false stops the rows not yet started.
  std::function<bool()> row_done;
};

// Writes map_x / map_y (row-major, width * height, filled beforehand with the value for
// "no pixel") where a pixel exists.
GridTableFill FillGridTable(const GridTableRequest& request, float* map_x, float* map_y);

}  // namespace omnical
