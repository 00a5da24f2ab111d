// Scalar helpers so one templated model serves double and ceres::Jet.
#pragma once

#include <ceres/jet.h>

#include <type_traits>

namespace omnical {

// The value part of a scalar: the double itself, or a Jet's .a (recursively).
inline double ScalarPart(double value) { return value; }
template <typename T, int N>
double ScalarPart(const ceres::Jet<T, N>& value) {
  return ScalarPart(value.a);
}

// Converts between scalar types: to double drops derivatives, from double makes a
// constant of the target type.
template <typename To, typename From>
To CastScalar(const From& value) {
  if constexpr (std::is_same_v<To, double>) {
    return ScalarPart(value);
  } else if constexpr (std::is_same_v<To, From>) {
    return value;
  } else {
    return To(ScalarPart(value));
  }
}

}  // namespace omnical
