// One-dimensional minimisation of a cost that need not be unimodal over the whole
// range: a coarse scan finds the best bracket, then Brent's method (Boost.Math) refines
// inside it. Used for the searched in-focus distance and the minimax viewpoint.
#pragma once

#include <boost/math/tools/minima.hpp>

#include <algorithm>
#include <cmath>

namespace omnical {

// Returns the minimiser in [lo, hi]; `scan` intervals for the coarse pass; the result is
// refined to about 1e-12 relative.
template <typename Cost>
double MinimizeScanThenBrent(const Cost& cost, double lo, double hi, int scan) {
  int best = 0;
  double best_cost = HUGE_VAL;
  for (int i = 0; i <= scan; ++i) {
    const double c = cost(lo + (hi - lo) * i / scan);
    if (c < best_cost) best_cost = c, best = i;
  }
  const double a = lo + (hi - lo) * std::max(best - 1, 0) / scan;
  const double b = lo + (hi - lo) * std::min(best + 1, scan) / scan;
  return boost::math::tools::brent_find_minima(cost, a, b, 40).first;
}

}  // namespace omnical
