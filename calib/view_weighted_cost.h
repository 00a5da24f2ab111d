// A cost function times a weight read through a pointer: the bundle fit's per-view noise
// weights (FitOptions::view_noise_weights), which change between solves without the
// problem being rebuilt. Residuals and Jacobians are both scaled, so the problem, its
// covariance and any loss see the weighted residual.
#pragma once

#include <ceres/cost_function.h>

#include <memory>

namespace omnical {

class ViewWeightedCost : public ceres::CostFunction {
 public:
  // Owns `cost`; `weight` must outlive this object's evaluations.
  ViewWeightedCost(ceres::CostFunction* cost, const double* weight) : cost_(cost), weight_(weight) {
    *mutable_parameter_block_sizes() = cost->parameter_block_sizes();
    set_num_residuals(cost->num_residuals());
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    if (!cost_->Evaluate(parameters, residuals, jacobians)) return false;
    const int rows = num_residuals();
    for (int r = 0; r < rows; ++r) residuals[r] *= *weight_;
    if (jacobians)
      for (size_t b = 0; b < parameter_block_sizes().size(); ++b)
        if (jacobians[b])
          for (int k = 0; k < rows * parameter_block_sizes()[b]; ++k) jacobians[b][k] *= *weight_;
    return true;
  }

 private:
  std::unique_ptr<ceres::CostFunction> cost_;
  const double* weight_;
};

}  // namespace omnical
