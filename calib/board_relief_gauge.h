// The board relief's gauge (BoardWarp::relief_mm, fitted by the bundle fit): the relief
// adds each corner's own offset along the board's normal, so a constant (the board moved
// along its normal, which every pose takes up) and the warp's two paraboloid factors
// (which the warp block moves) are in its span with nothing in the data to tell them
// apart. Left to the relief's prior alone they made the warp's std 0.39 mm on the real Mei
// set where the data give 0.07. So the relief is held orthogonal to those three shapes
// over the fitted corners: what is reported is the board's shape less its mean and its
// paraboloid. Not the planes x and y: a tilt of the board takes them up only to first
// order (it also moves the bent corners within the plane, by the tilt times their
// offset), so held too they cost exact corners of a 1.5 mm bump 0.002 px
// (tests/bundle_fit_test.cc); the data and the prior settle them. A residual block over
// every relief block, (noise / kReliefGaugeStdMm) Q^T relief with Q an orthonormal basis
// of the shapes: weighted by the corner noise as the priors are (calib/bundle_fit.cc,
// PriorCost), so in the covariance, scaled by 1 / sigma with the data, it enters as rows of
// 1 / kReliefGaugeStdMm.
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <Eigen/QR>
#include <algorithm>
#include <vector>

namespace omnical {

// Tight enough that the held directions carry no variance worth reporting (1e-6 mm^2),
// loose enough to keep the normal equations well conditioned (1e3 per mm against the
// corners' tens of px per mm over a few tenths of a px of noise).
constexpr double kReliefGaugeStdMm = 1e-3;

class BoardReliefGaugeCost : public ceres::CostFunction {
 public:
  // shapes: per relief block (in the order the blocks are passed) its row (1, bx, by).
  BoardReliefGaugeCost(const Eigen::MatrixXd& shapes, const double* noise_px) : noise_px_(noise_px) {
    // Only the shapes' rank: a board one corner wide along an axis has no paraboloid along it.
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(shapes);
    basis_ = Eigen::MatrixXd(qr.householderQ()).leftCols(qr.rank());
    set_num_residuals(static_cast<int>(basis_.cols()));
    for (Eigen::Index i = 0; i < shapes.rows(); ++i) mutable_parameter_block_sizes()->push_back(1);
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double weight = *noise_px_ / kReliefGaugeStdMm;
    Eigen::Map<Eigen::VectorXd> out(residuals, basis_.cols());
    out.setZero();
    for (Eigen::Index i = 0; i < basis_.rows(); ++i) out += weight * parameters[i][0] * basis_.row(i).transpose();
    if (jacobians)
      for (Eigen::Index i = 0; i < basis_.rows(); ++i)
        if (jacobians[i])
          for (Eigen::Index k = 0; k < basis_.cols(); ++k) jacobians[i][k] = weight * basis_(i, k);
    return true;
  }

 private:
  Eigen::MatrixXd basis_;  // orthonormal columns spanning the shapes
  const double* noise_px_;
};

}  // namespace omnical
