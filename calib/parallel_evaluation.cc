#include "calib/parallel_evaluation.h"

#include <algorithm>
#include <cstring>
#include <memory>

#include "model/parallel_rows.h"

namespace omnical {

class ParallelEvaluation::CachedCost : public ceres::CostFunction {
 public:
  CachedCost(ParallelEvaluation* owner, size_t index, ceres::CostFunction* inner, const std::vector<double*>& parameters)
      : owner_(owner), index_(index), inner_(inner), parameters_(parameters) {
    set_num_residuals(inner->num_residuals());
    *mutable_parameter_block_sizes() = inner->parameter_block_sizes();
    compute_jacobian_.assign(parameters.size(), true);
    size_t values = 0;
    for (int32_t size : parameter_block_sizes()) {
      jacobian_offsets_.push_back(values * num_residuals());
      values += size;
    }
    values_.resize(values);
    residuals_.resize(num_residuals());
    jacobians_.resize(values * num_residuals());
  }
  ~CachedCost() override { owner_->Forget(this); }

  size_t index() const { return index_; }
  void set_index(size_t index) { index_ = index; }

  void UpdateConstantBlocks(const ceres::Problem& problem) {
    for (size_t b = 0; b < parameters_.size(); ++b) {
      const bool variable = !problem.IsParameterBlockConstant(parameters_[b]);
      // A block that was constant has no Jacobian in the cache.
      if (variable != compute_jacobian_[b]) state_ = State::kEmpty;
      compute_jacobian_[b] = variable;
    }
  }

  // Evaluates at the current values of the parameter blocks, into the cache.
  void Compute(bool with_jacobians) {
    state_ = State::kEmpty;  // until the evaluation below has filled it
    size_t k = 0;
    for (size_t b = 0; b < parameters_.size(); ++b)
      for (int32_t i = 0; i < parameter_block_sizes()[b]; ++i) values_[k++] = parameters_[b][i];
    std::vector<double*> jacobians(parameters_.size(), nullptr);
    if (with_jacobians)
      for (size_t b = 0; b < parameters_.size(); ++b)
        if (compute_jacobian_[b]) jacobians[b] = jacobians_.data() + jacobian_offsets_[b];
    ok_ = inner_->Evaluate(parameters_.data(), residuals_.data(), with_jacobians ? jacobians.data() : nullptr);
    state_ = with_jacobians ? State::kWithJacobians : State::kResiduals;
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    if (!Answers(parameters, jacobians)) return inner_->Evaluate(parameters, residuals, jacobians);
    if (!ok_) return false;
    std::copy(residuals_.begin(), residuals_.end(), residuals);
    if (jacobians != nullptr)
      for (size_t b = 0; b < parameters_.size(); ++b)
        if (jacobians[b] != nullptr)
          std::copy_n(jacobians_.data() + jacobian_offsets_[b], num_residuals() * parameter_block_sizes()[b], jacobians[b]);
    return true;
  }

 private:
  enum class State { kEmpty, kResiduals, kWithJacobians };

  // Whether the cache holds what is asked, at these very values.
  bool Answers(double const* const* parameters, double** jacobians) const {
    if (state_ == State::kEmpty) return false;
    if (jacobians != nullptr) {
      if (state_ != State::kWithJacobians) return false;
      for (size_t b = 0; b < parameters_.size(); ++b)
        if (jacobians[b] != nullptr && !compute_jacobian_[b]) return false;
    }
    size_t k = 0;
    for (size_t b = 0; b < parameters_.size(); ++b) {
      const size_t size = parameter_block_sizes()[b];
      if (std::memcmp(parameters[b], values_.data() + k, size * sizeof(double)) != 0) return false;
      k += size;
    }
    return true;
  }

  ParallelEvaluation* owner_;
  size_t index_;  // in owner_->costs_
  std::unique_ptr<ceres::CostFunction> inner_;
  std::vector<double*> parameters_;
  std::vector<bool> compute_jacobian_;
  std::vector<size_t> jacobian_offsets_;
  std::vector<double> values_, residuals_, jacobians_;
  bool ok_ = false;
  State state_ = State::kEmpty;
};

ceres::CostFunction* ParallelEvaluation::Wrap(ceres::CostFunction* cost, const std::vector<double*>& parameters) {
  auto* cached = new CachedCost(this, costs_.size(), cost, parameters);
  costs_.push_back(cached);
  return cached;
}

void ParallelEvaluation::Forget(const CachedCost* cost) {
  // The last one takes its place: the order of computing does not change any value.
  CachedCost* last = costs_.back();
  costs_[cost->index()] = last;
  last->set_index(cost->index());
  costs_.pop_back();
}

void ParallelEvaluation::UpdateConstantBlocks(const ceres::Problem& problem) {
  for (CachedCost* cost : costs_) cost->UpdateConstantBlocks(problem);
  have_jacobians_ = false;  // computed for other blocks
}

void ParallelEvaluation::PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) {
  if (!new_evaluation_point && (have_jacobians_ || !evaluate_jacobians)) return;
  // Chunks of a few costs handed out one at a time: a corner whose solve fails is cheap.
  constexpr int kChunk = 16;
  const int count = static_cast<int>(costs_.size());
  ParallelRows((count + kChunk - 1) / kChunk, threads_, [&](int chunk) {
    for (int k = chunk * kChunk; k < std::min(count, (chunk + 1) * kChunk); ++k) costs_[k]->Compute(evaluate_jacobians);
  });
  have_jacobians_ = evaluate_jacobians;
}

}  // namespace omnical
