// The bundle fit's residuals and Jacobians computed on a few threads before Ceres asks for
// them (a ceres::EvaluationCallback), while Ceres itself runs on one thread.
//
// Why not Ceres' own threads: its Schur eliminator sums blocks in thread order, so on two
// threads the same calibration differed in the 8th digit from run to run, and the CLI and
// the Python module must agree (calib/fit_options.h). The corners' costs, three quarters of
// a fit's time, are independent of each other: computed here, each by one thread, they are
// the very numbers one thread computes, and the fit is bit-identical for any thread count
// (tests/bundle_fit_test.cc).
//
// Each wrapped cost answers Ceres from its cache when the parameter values Ceres passes are
// bitwise those the cache was computed at and the cache holds what is asked for, and
// otherwise evaluates itself: a stale cache can cost time, never a wrong number.
#pragma once

#include <ceres/cost_function.h>
#include <ceres/evaluation_callback.h>
#include <ceres/problem.h>

#include <vector>

namespace omnical {

class ParallelEvaluation : public ceres::EvaluationCallback {
 public:
  explicit ParallelEvaluation(int threads) : threads_(threads) {}
  ParallelEvaluation(const ParallelEvaluation&) = delete;
  ParallelEvaluation& operator=(const ParallelEvaluation&) = delete;

  // A cost function answering from this evaluation's cache, to add to the problem in place
  // of `cost` (owned by it) at `parameters` (the problem's parameter blocks). The problem
  // must not outlive this object.
  ceres::CostFunction* Wrap(ceres::CostFunction* cost, const std::vector<double*>& parameters);

  // Which Jacobian blocks the coming evaluations compute: those of the blocks `problem`
  // does not hold constant. Call before each Solve (what is constant changes between them).
  void UpdateConstantBlocks(const ceres::Problem& problem);

  void PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) override;

 private:
  class CachedCost;
  friend class CachedCost;
  void Forget(const CachedCost* cost);

  int threads_;
  std::vector<CachedCost*> costs_;  // the live ones: a removed residual block's cost forgets itself
  bool have_jacobians_ = false;
};

}  // namespace omnical
