// The bundle fit's cost (calib/bundle_fit.h): the exact non-central reprojection error of
// one target corner, for any registered lens x profile (model/model_registry.h).
//
// Parameter blocks, in this order (BlockSizes):
//   lens        Lens::kNumParams, the lens's ToParams order
//   m           1 (mm)
//   tilt        2 (rad: x, y)
//   decenter    2 (mm: x, y)
//   shape       the profile's NumParams(), its ToParams order; absent when 0 (tabulated)
//   rotation    4: camera_from_target as Eigen's quaternion coefficients x, y, z, w
//   translation 3: camera_from_target (mm)
//   warp        2 (mm), only when the cost is created with a warp basis: the board's
//               out-of-plane deflection at its centre along its x and y axes (BoardWarp)
//   relief      1 (mm), only when created with_relief: this corner's own out-of-plane
//               offset on top of the warp (BoardWarp::relief_mm)
// Residual: predicted minus observed pixel (2). Evaluation fails (returns false) where the
// optics have no reflection point: Ceres then treats the step as invalid.
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cstring>
#include <numeric>
#include <optional>
#include <vector>

#include "model/catadioptric.h"

namespace omnical {

template <template <typename> class Profile, template <typename> class Lens>
class ReprojectionCost {
 public:
  using Model = Catadioptric<double, Profile, Lens>;

  // base: the rim, image size, the profile's parameter count (a tabulated profile's table).
  // warp_basis: the corner's BoardWarp::Basis when the warp block is present.
  ReprojectionCost(const Model& base, const Eigen::Vector3d& point_in_target_mm, const Eigen::Vector2d& observed_px,
                   const std::optional<Eigen::Vector2d>& warp_basis = std::nullopt, bool with_relief = false)
      : base_(base),
        point_in_target_mm_(point_in_target_mm),
        observed_px_(observed_px),
        warp_basis_(warp_basis),
        with_relief_(with_relief),
        block_sizes_(BlockSizes(base, warp_basis.has_value(), with_relief)),
        last_scalars_(std::accumulate(block_sizes_.begin(), block_sizes_.end(), size_t{0})) {
    // The corner was detected, so its reflection lies on the mirror; iterates may stray a
    // little past the rim, where the profile is still defined.
    base_.rim_radius_mm = std::min(1.15 * base.rim_radius_mm, 0.99 * base.mirror.MaxRadiusMm());
  }

  template <typename T>
  bool operator()(T const* const* p, T* residual) const {
    Catadioptric<T, Profile, Lens> model;
    model.lens = Lens<T>::FromParams(p[0]);
    model.pose = MirrorPose<T>{p[1][0], p[2][0], p[2][1], p[3][0], p[3][1]};
    int next = 4;
    model.mirror = HasShape() ? base_.mirror.template WithParams<T>(p[next++]) : base_.mirror.template Cast<T>();
    model.rim_radius_mm = base_.rim_radius_mm;
    model.image_width_px = base_.image_width_px;
    model.image_height_px = base_.image_height_px;
    const Eigen::Quaternion<T> rotation(p[next][3], p[next][0], p[next][1], p[next][2]);
    Vec3<T> in_target = point_in_target_mm_.cast<T>();
    if (warp_basis_) in_target.z() += p[next + 2][0] * T(warp_basis_->x()) + p[next + 2][1] * T(warp_basis_->y());
    if (with_relief_) in_target.z() += p[next + (warp_basis_ ? 3 : 2)][0];
    const Vec3<T> in_camera = rotation * in_target + Vec3<T>(p[next + 1][0], p[next + 1][1], p[next + 1][2]);
    Vec3<T> mirror_point;
    // The corner was detected: no image-bounds or occlusion test, only the optics.
    solved_.reuse = SameScalarsAsLastCall(p);
    if (model.ReflectionPoint(in_camera, &mirror_point, nullptr, &solved_) != ProjectionStatus::kOk) return false;
    Vec2<T> pixel;
    if (!model.lens.ProjectToPixel(mirror_point, &pixel)) return false;
    residual[0] = pixel(0) - T(observed_px_.x());
    residual[1] = pixel(1) - T(observed_px_.y());
    return true;
  }

  // The blocks' sizes, in the order above.
  static std::vector<int> BlockSizes(const Model& base, bool with_warp = false, bool with_relief = false) {
    std::vector<int> sizes = {Lens<double>::kNumParams, 1, 2, 2};
    if (base.mirror.NumParams() > 0) sizes.push_back(base.mirror.NumParams());
    sizes.push_back(4);
    sizes.push_back(3);
    if (with_warp) sizes.push_back(2);
    if (with_relief) sizes.push_back(1);
    return sizes;
  }

  // Automatic derivatives (Jets through the implicit solve: model/catadioptric.h).
  static ceres::CostFunction* Create(const Model& base, const Eigen::Vector3d& point_in_target_mm,
                                     const Eigen::Vector2d& observed_px,
                                     const std::optional<Eigen::Vector2d>& warp_basis = std::nullopt,
                                     bool with_relief = false) {
    auto* cost = new ceres::DynamicAutoDiffCostFunction<ReprojectionCost, 8>(
        new ReprojectionCost(base, point_in_target_mm, observed_px, warp_basis, with_relief));
    for (int size : BlockSizes(base, warp_basis.has_value(), with_relief)) cost->AddParameterBlock(size);
    cost->SetNumResiduals(2);
    return cost;
  }

  const Eigen::Vector3d& point_in_target_mm() const { return point_in_target_mm_; }

 private:
  bool HasShape() const { return base_.mirror.NumParams() > 0; }

  // Whether the parameters' values (a Jet's scalar part) are those of the last call, which
  // are then kept for the next. The parameters determine everything the solve sees.
  template <typename T>
  bool SameScalarsAsLastCall(T const* const* p) const {
    size_t k = 0;
    bool same = called_before_;
    called_before_ = true;
    for (size_t b = 0; b < block_sizes_.size(); ++b)
      for (int i = 0; i < block_sizes_[b]; ++i, ++k) {
        const double value = ScalarPart(p[b][i]);
        // Bitwise: -0.0 and 0.0 may take different branches, and NaN never equals itself.
        same = same && std::memcmp(&value, &last_scalars_[k], sizeof value) == 0;
        last_scalars_[k] = value;
      }
    return same;
  }

  Model base_;
  Eigen::Vector3d point_in_target_mm_;
  Eigen::Vector2d observed_px_;
  std::optional<Eigen::Vector2d> warp_basis_;
  bool with_relief_ = false;
  std::vector<int> block_sizes_;
  // The last call's parameter values and reflection point (model/catadioptric.h,
  // SolvedReflection): the Jet passes of one Jacobian, and a Jacobian after a plain residual
  // at the same point, solve once. Mutable state in a cost is safe: each corner has its own
  // cost, evaluated by one thread at a time (Ceres, calib/parallel_evaluation.h).
  mutable std::vector<double> last_scalars_;
  mutable bool called_before_ = false;
  mutable SolvedReflection solved_;
};

// The cost of a model type. Deduced from the Catadioptric's own template arguments: clang
// (unlike GCC) treats Model::ProfileOf, an alias template, as a template distinct from the
// profile itself (CWG 1286), and the functor's model type would then mismatch.
template <typename Model>
struct ReprojectionCostOf;
template <template <typename> class Profile, template <typename> class Lens>
struct ReprojectionCostOf<Catadioptric<double, Profile, Lens>> {
  using type = ReprojectionCost<Profile, Lens>;
};

}  // namespace omnical
