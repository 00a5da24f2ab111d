// The covariance of a bundle fit (calib/bundle_fit.h) and what it says about trust.
//
// Estimated as (J^T J)^-1 at the solution, J the corner residuals over the noise sigma
// with one row 1 / tolerance per design prior beneath (the posterior of a Gaussian
// prior), over every free column, poses included: the sensor's block of the inverse is
// its covariance with the poses marginalised, full (every correlation kept).
#pragma once

#include <ceres/problem.h>

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "model/parameter_field.h"

namespace omnical {

struct PriorRow {
  int column;          // in the free columns of the evaluated blocks
  double inverse_std;  // 1 / tolerance, internal units
};

// The covariance of every free column of `variable_blocks` (Ceres' tangent order, poses
// included), from the residual blocks `data_blocks` (robust loss not applied) scaled by
// 1 / sigma_px and the prior rows. False when J is rank deficient: a gauge left free.
bool EstimateCovariance(ceres::Problem* problem, const std::vector<double*>& variable_blocks,
                        const std::vector<ceres::ResidualBlockId>& data_blocks, const std::vector<PriorRow>& priors,
                        double sigma_px, Eigen::MatrixXd* covariance);

// The correlation matrix of a covariance (unit diagonal; 0 where a variance is 0).
Eigen::MatrixXd CorrelationOf(const Eigen::MatrixXd& covariance);

// A weakly determined parameter, for calibration warnings.
struct CovarianceFinding {
  std::string parameter;
  std::string text;  // one line for the user
};

struct CovarianceParameter {
  std::string name;
  double value;
  ParameterGroup group;
  bool scale_like;
};

constexpr double kWeakTiltStdDeg = 2.0;
// A scale-like parameter is weakly determined past this std relative to its value.
constexpr double kWeakRelativeStd = 0.05;

// The free scale-like parameters whose std exceeds kWeakRelativeStd of their value, and tilts known to
// no better than kWeakTiltStdDeg (the others are
// naturally near zero, where a relative std means nothing), each named with the parameter
// of another group it is most correlated with when that correlation is >= 0.9: the valley
// it moves along (fx with m is the
// "dolly zoom": the lens sees the mirror under a small angle). Parameters in the
// covariance's order.
std::vector<CovarianceFinding> WeakParameters(const std::vector<CovarianceParameter>& parameters,
                                              const Eigen::MatrixXd& covariance);

// How open the dolly-zoom valley is: the condition number of the correlation matrix of one
// parameter per scale: the lens focal length (fx or the orthographic scale), m and the
// mirror's size (its first scale-like shape parameter), those that are free. 1 for fewer
// than two; NaN without a covariance. Reported, not warned on: on the bundled sets it
// ranges 2e4-6e6 and does not separate good calibrations from bad ones (the relative stds
// do).
double ScaleBlockCondition(const std::vector<CovarianceParameter>& parameters, const Eigen::MatrixXd& covariance);

}  // namespace omnical
