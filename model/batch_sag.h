// The profile a batch kernel evaluates: the sensor's own, except where its EvaluateSag
// has a loop whose length is only known at run time, which keeps a loop over points
// from vectorising. The even polynomial's Horner loop becomes one over all eight slots
// with the unused ones zero: the extra terms add exact zeros, so every finite sag and
// derivative is bit-identical to EvenPolynomialProfile's (an infinite r^2 may give NaN
// instead of inf; such points fail the batch's checks either way).
#pragma once

#include <array>

#include "model/mirror_profiles.h"

namespace omnical {

struct PaddedPolynomialProfile {
  static constexpr int kSlots = EvenPolynomialProfile<double>::kMaxCoefficients;
  std::array<double, kSlots> coefficients{};

  SagDerivatives<double> EvaluateSag(double r2) const {
    double p = 0.0, dp = 0.0, ddp = 0.0;
    for (int k = kSlots - 1; k >= 0; --k) {
      ddp = ddp * r2 + 2.0 * dp;
      dp = dp * r2 + p;
      p = p * r2 + coefficients[k];
    }
    return {r2 * p, p + r2 * dp, 2.0 * dp + r2 * ddp};
  }
};

template <typename Profile>
const Profile& BatchProfile(const Profile& profile) {
  return profile;
}

inline PaddedPolynomialProfile BatchProfile(const EvenPolynomialProfile<double>& profile) {
  PaddedPolynomialProfile padded;
  for (int k = 0; k < profile.num_coefficients; ++k) padded.coefficients[k] = profile.coefficients[k];
  return padded;
}

}  // namespace omnical
