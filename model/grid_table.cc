#include "model/grid_table.h"

#include "model/parallel_rows.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <vector>

namespace omnical {
namespace {

// Weights of the cubic through nodes at -1, 0, 1, 2 (in steps) evaluated at t in [0, 1].
std::array<double, 4> CubicWeights(double t) {
  return {-t * (t - 1.0) * (t - 2.0) / 6.0, (t + 1.0) * (t - 1.0) * (t - 2.0) / 2.0,
          -(t + 1.0) * t * (t - 2.0) / 2.0, (t + 1.0) * t * (t - 1.0) / 6.0};
}

}  // namespace

int NodeStepPx(double pixel_rad) {
  if (!(pixel_rad > 0.0)) return 2;
  return std::clamp(static_cast<int>(kNodeSpacingDeg * 3.14159265358979323846 / 180.0 / pixel_rad), 2, 64);
}

// Node (i, j) sits at table point ((i - 1) step, (j - 1) step): one node beyond each side,
// so that the pixel u in cell a = u / step has the nodes a .. a + 3 around it.
GridTableFill FillGridTable(const GridTableRequest& request, float* map_x, float* map_y) {
  const int step = std::max(2, request.step_px);
  const int width = request.width, height = request.height;
  const int node_cols = (width - 1) / step + 4, node_rows = (height - 1) / step + 4;
  const int cell_cols = node_cols - 3, cell_rows = node_rows - 3;
  // Each node row, and its cubic along the row at every table column (NaN where a node
  // is missing), so that a pixel needs only the cubic across 4 of these rows.
  std::vector<double> nodes_x(static_cast<size_t>(node_cols) * node_rows), nodes_y(nodes_x.size());
  std::vector<double> along_x(static_cast<size_t>(width) * node_rows), along_y(along_x.size());
  std::vector<std::array<double, 4>> column_weights(width);
  for (int u = 0; u < width; ++u) column_weights[u] = CubicWeights(double(u % step) / step);
  ParallelRows(node_rows, request.threads, [&](int j) {
    Eigen::Matrix2Xd table_points(2, node_cols);
    for (int i = 0; i < node_cols; ++i) table_points.col(i) = Eigen::Vector2d((i - 1.0) * step, (j - 1.0) * step);
    const Eigen::Matrix2Xd pixels = request.project(table_points);
    double* node_x = &nodes_x[static_cast<size_t>(j) * node_cols];
    double* node_y = &nodes_y[static_cast<size_t>(j) * node_cols];
    for (int i = 0; i < node_cols; ++i) node_x[i] = pixels(0, i), node_y[i] = pixels(1, i);
    for (int u = 0; u < width; ++u) {
      const int a = u / step;
      const std::array<double, 4>& w = column_weights[u];
      along_x[static_cast<size_t>(j) * width + u] = w[0] * node_x[a] + w[1] * node_x[a + 1] + w[2] * node_x[a + 2] + w[3] * node_x[a + 3];
      along_y[static_cast<size_t>(j) * width + u] = w[0] * node_y[a] + w[1] * node_y[a + 1] + w[2] * node_y[a + 2] + w[3] * node_y[a + 3];
    }
  });

  // Cells: interpolated only with all 16 nodes and a centre within the check tolerance.
  std::vector<char> interpolated(static_cast<size_t>(cell_cols) * cell_rows, 0);
  std::vector<double> worst_check(cell_rows, 0.0);
  ParallelRows(cell_rows, request.threads, [&](int b) {
    const std::array<double, 4> w = CubicWeights(0.5);
    Eigen::Matrix2Xd centres(2, cell_cols), guesses(2, cell_cols);
    for (int a = 0; a < cell_cols; ++a) {
      centres.col(a) = Eigen::Vector2d((a + 0.5) * step, (b + 0.5) * step);
      Eigen::Vector2d guess = Eigen::Vector2d::Zero();
      for (int k = 0; k < 4; ++k)
        for (int l = 0; l < 4; ++l) {
          const size_t node = static_cast<size_t>(b + k) * node_cols + a + l;
          guess += w[k] * w[l] * Eigen::Vector2d(nodes_x[node], nodes_y[node]);
        }
      guesses.col(a) = guess;  // NaN if a node is missing
    }
    const Eigen::Matrix2Xd exact = request.project(centres);
    for (int a = 0; a < cell_cols; ++a) {
      const double miss = (guesses.col(a) - exact.col(a)).cwiseAbs().maxCoeff();  // NaN fails below
      if (miss < kCellCheckTolerancePx) {
        interpolated[static_cast<size_t>(b) * cell_cols + a] = 1;
        worst_check[b] = std::max(worst_check[b], miss);
      }
    }
  });

  std::atomic<long> valid{0}, exact_pixels{0};
  std::atomic<bool> stopped{false};
  ParallelRows(height, request.threads, [&](int v) {
    if (stopped) return;
    const int b = v / step;
    const std::array<double, 4> w = CubicWeights(double(v % step) / step);
    const size_t row0 = static_cast<size_t>(b) * width;
    const size_t stride = width;
    std::vector<int> exact_columns;
    long row_valid = 0;
    for (int u = 0; u < width; ++u) {
      if (!interpolated[static_cast<size_t>(b) * cell_cols + u / step]) {
        exact_columns.push_back(u);
        continue;
      }
      const size_t k = row0 + u;
      const double x = w[0] * along_x[k] + w[1] * along_x[k + stride] + w[2] * along_x[k + 2 * stride] + w[3] * along_x[k + 3 * stride];
      const double y = w[0] * along_y[k] + w[1] * along_y[k + stride] + w[2] * along_y[k + 2 * stride] + w[3] * along_y[k + 3 * stride];
      if (request.keep && !request.keep(x, y)) continue;
      const size_t i = static_cast<size_t>(v) * width + u;
      map_x[i] = static_cast<float>(x);
      map_y[i] = static_cast<float>(y);
      ++row_valid;
    }
    if (!exact_columns.empty()) {
      Eigen::Matrix2Xd table_points(2, exact_columns.size());
      for (size_t c = 0; c < exact_columns.size(); ++c) table_points.col(c) = Eigen::Vector2d(exact_columns[c], v);
      const Eigen::Matrix2Xd pixels = request.project(table_points);
      long projected = 0;
      for (size_t c = 0; c < exact_columns.size(); ++c) {
        if (std::isnan(pixels(0, c))) continue;
        const size_t i = static_cast<size_t>(v) * width + exact_columns[c];
        map_x[i] = static_cast<float>(pixels(0, c));
        map_y[i] = static_cast<float>(pixels(1, c));
        ++projected;
      }
      row_valid += projected;
      exact_pixels += projected;
    }
    valid += row_valid;
    if (request.row_done && !request.row_done()) stopped = true;
  });
  GridTableFill fill;
  fill.valid_pixels = valid;
  fill.exact_pixels = exact_pixels;
  fill.worst_cell_check_px = *std::max_element(worst_check.begin(), worst_check.end());
  return fill;
}

}  // namespace omnical
