#include "calib/fit_covariance.h"

#include <ceres/crs_matrix.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "calib/fit_options.h"

namespace omnical {

bool EstimateCovariance(ceres::Problem* problem, const std::vector<double*>& variable_blocks,
                        const std::vector<ceres::ResidualBlockId>& data_blocks, const std::vector<PriorRow>& priors,
                        double sigma_px, Eigen::MatrixXd* covariance) {
  if (data_blocks.empty()) return false;
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = variable_blocks;
  evaluate.residual_blocks = data_blocks;
  evaluate.apply_loss_function = false;
  ceres::CRSMatrix crs;
  if (!problem->Evaluate(evaluate, nullptr, nullptr, nullptr, &crs)) return false;
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(crs.num_rows + static_cast<int>(priors.size()), crs.num_cols);
  const double inverse_sigma = 1.0 / std::max(sigma_px, 1e-12);
  for (int r = 0; r < crs.num_rows; ++r)
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) jacobian(r, crs.cols[k]) = crs.values[k] * inverse_sigma;
  for (size_t p = 0; p < priors.size(); ++p) jacobian(crs.num_rows + p, priors[p].column) = priors[p].inverse_std;
  // The columns differ by many orders of magnitude (a polynomial's c3 multiplies r^6), so
  // they are scaled to unit norm before the SVD: a truncated decomposition would otherwise
  // discard well-determined directions and report their variance as zero.
  const Eigen::VectorXd column_scale = jacobian.colwise().norm().transpose();
  if (!(column_scale.array() > 0.0).all() || jacobian.rows() < jacobian.cols()) return false;
  const Eigen::MatrixXd scaled = jacobian * column_scale.cwiseInverse().asDiagonal();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeThinV);
  const Eigen::VectorXd& singular = svd.singularValues();
  // Rank check on the scaled problem: a real degeneracy (a gauge left free) shows here.
  if (!(singular.minCoeff() > 1e-10 * singular.maxCoeff())) return false;
  const Eigen::MatrixXd v = column_scale.cwiseInverse().asDiagonal() * svd.matrixV() * singular.cwiseInverse().asDiagonal();
  *covariance = v * v.transpose();
  return true;
}

Eigen::MatrixXd CorrelationOf(const Eigen::MatrixXd& covariance) {
  const Eigen::VectorXd std = covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  Eigen::MatrixXd correlation = Eigen::MatrixXd::Identity(covariance.rows(), covariance.cols());
  for (int i = 0; i < covariance.rows(); ++i)
    for (int j = 0; j < covariance.cols(); ++j)
      if (i != j && std(i) > 0.0 && std(j) > 0.0) correlation(i, j) = covariance(i, j) / (std(i) * std(j));
  return correlation;
}

namespace {

// One parameter per scale: the first focal, the first m, the first scale-like shape one.
std::vector<int> ScaleBlockIndices(const std::vector<CovarianceParameter>& parameters) {
  std::vector<int> indices;
  for (ParameterGroup group : {ParameterGroup::kFocal, ParameterGroup::kMirrorDistance, ParameterGroup::kShape})
    for (size_t k = 0; k < parameters.size(); ++k)
      if (parameters[k].group == group && parameters[k].scale_like) {
        indices.push_back(static_cast<int>(k));
        break;
      }
  return indices;
}

}  // namespace

double ScaleBlockCondition(const std::vector<CovarianceParameter>& parameters, const Eigen::MatrixXd& covariance) {
  if (covariance.size() == 0) return NAN;
  const std::vector<int> indices = ScaleBlockIndices(parameters);
  if (indices.size() < 2) return 1.0;
  const Eigen::MatrixXd correlation = CorrelationOf(covariance);
  Eigen::MatrixXd block(indices.size(), indices.size());
  for (size_t i = 0; i < indices.size(); ++i)
    for (size_t j = 0; j < indices.size(); ++j) block(i, j) = correlation(indices[i], indices[j]);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(block, Eigen::EigenvaluesOnly);
  const double smallest = eigen.eigenvalues().minCoeff(), largest = eigen.eigenvalues().maxCoeff();
  return smallest > 0.0 ? largest / smallest : HUGE_VAL;
}

std::vector<CovarianceFinding> WeakParameters(const std::vector<CovarianceParameter>& parameters,
                                              const Eigen::MatrixXd& covariance) {
  std::vector<CovarianceFinding> findings;
  if (covariance.rows() != static_cast<int>(parameters.size()) || parameters.empty()) return findings;
  const Eigen::MatrixXd correlation = CorrelationOf(covariance);
  for (size_t k = 0; k < parameters.size(); ++k) {
    const CovarianceParameter& p = parameters[k];
    const double std = std::sqrt(std::max(0.0, covariance(k, k)));
    // Scale-like: relative to the value. A tilt: beyond 2 deg it is not determined at all
    // (a nearly spherical mirror turned about its centre; the bundled sets reach 1.1 deg
    // at worst).
    const bool weak = p.scale_like ? p.value != 0.0 && std > kWeakRelativeStd * std::abs(p.value)
                                    : p.group == ParameterGroup::kTilt && std > kWeakTiltStdDeg;
    if (!weak) continue;
    char spread[80];
    if (p.scale_like) {
      std::snprintf(spread, sizeof spread, "std %.1f%% of its value", 100.0 * std / std::abs(p.value));
    } else {
      std::snprintf(spread, sizeof spread, "std %.2g deg", std);
    }
    int partner = -1;
    for (size_t j = 0; j < parameters.size(); ++j)
      if (parameters[j].group != p.group && (partner < 0 || std::abs(correlation(k, j)) > std::abs(correlation(k, partner))))
        partner = static_cast<int>(j);
    char text[400];
    // A partner is named only where it explains the spread (|r| >= 0.9: it carries 80 %
    // of the variance); a weak correlation would mislead.
    if (partner >= 0 && std::abs(correlation(k, partner)) >= 0.9) {
      std::snprintf(text, sizeof text,
                    "%s is weakly determined (%s): it trades off with %s (correlation %.3f); hold %s or %s at its "
                    "design value (--fix %s or --fix %s), give a design tolerance, or add views at more distances",
                    p.name.c_str(), spread, parameters[partner].name.c_str(), correlation(k, partner),
                    HoldName(p.group), HoldName(parameters[partner].group), HoldName(p.group),
                    HoldName(parameters[partner].group));
    } else {
      std::snprintf(text, sizeof text,
                    "%s is weakly determined (%s): views covering more of the mirror, at more distances, help",
                    p.name.c_str(), spread);
    }
    findings.push_back({p.name, text});
  }
  return findings;
}

}  // namespace omnical
