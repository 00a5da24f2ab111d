// Ceres' iteration callback forwarding to a ProgressReporter (model/progress.h): one step
// per solver iteration; a false from the caller aborts the solve, and the job throws
// Cancelled once Solve returns (ThrowIfCancelled).
#pragma once

#include <ceres/iteration_callback.h>

#include "model/progress.h"

namespace omnical {

class IterationProgress : public ceres::IterationCallback {
 public:
  explicit IterationProgress(ProgressReporter* reporter) : reporter_(reporter) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return reporter_->Advance() ? ceres::SOLVER_CONTINUE : ceres::SOLVER_ABORT;
  }

 private:
  ProgressReporter* reporter_;
};

}  // namespace omnical
