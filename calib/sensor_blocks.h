// A sensor's parameters as the bundle fit's parameter blocks (calib/reprojection_cost.h),
// packed and unpacked through the registry (model/model_registry.h): no profile or lens
// is named here.
#pragma once

#include <cmath>
#include <vector>

#include "model/model_registry.h"

namespace omnical {

template <typename Model>
struct SensorBlocks {
  std::vector<double> lens;
  double m_mm = 0.0;
  double tilt_rad[2] = {0.0, 0.0};
  double decenter_mm[2] = {0.0, 0.0};
  std::vector<double> shape;  // empty for a tabulated profile

  explicit SensorBlocks(const Model& model) : base_(model) {
    lens.resize(Model::LensType::kNumParams);
    model.lens.ToParams(lens.data());
    m_mm = model.pose.m_mm;
    tilt_rad[0] = model.pose.tilt_x_rad, tilt_rad[1] = model.pose.tilt_y_rad;
    decenter_mm[0] = model.pose.decenter_x_mm, decenter_mm[1] = model.pose.decenter_y_mm;
    shape.resize(model.mirror.NumParams());
    model.mirror.ToParams(shape.data());
  }
  SensorBlocks(const SensorBlocks&) = delete;  // the fit holds pointers into the blocks
  SensorBlocks& operator=(const SensorBlocks&) = delete;

  // The base model with these blocks' values.
  Model ToModel() const {
    Model model = base_;
    model.lens = Model::LensType::FromParams(lens.data());
    model.pose = MirrorPose<double>{m_mm, tilt_rad[0], tilt_rad[1], decenter_mm[0], decenter_mm[1]};
    if (!shape.empty()) model.mirror = base_.mirror.WithParams(shape.data());
    return model;
  }

  // The sensor's blocks in the cost's order: lens, m, tilt, decenter[, shape].
  std::vector<double*> Pointers() {
    std::vector<double*> blocks = {lens.data(), &m_mm, tilt_rad, decenter_mm};
    if (!shape.empty()) blocks.push_back(shape.data());
    return blocks;
  }
  int BlockSize(const double* block) const {
    if (block == lens.data()) return static_cast<int>(lens.size());
    if (block == &m_mm) return 1;
    if (block == shape.data()) return static_cast<int>(shape.size());
    return 2;
  }

  // each(info, block, index, scale to reported units) for every parameter, in the
  // registry's order (SensorParameterInfos). Tilts are reported in degrees.
  template <typename Each>
  void ForEach(const Each& each) {
    const std::vector<ParameterInfo> infos = SensorParameterInfos(base_);
    size_t next = 0;
    for (int k = 0; k < static_cast<int>(lens.size()); ++k) each(infos[next++], lens.data(), k, 1.0);
    each(infos[next++], &m_mm, 0, 1.0);
    for (int k = 0; k < 2; ++k) each(infos[next++], tilt_rad, k, 180.0 / M_PI);
    for (int k = 0; k < 2; ++k) each(infos[next++], decenter_mm, k, 1.0);
    for (int k = 0; k < static_cast<int>(shape.size()); ++k) each(infos[next++], shape.data(), k, 1.0);
  }

  // The lens entries of a group (indices into `lens`).
  static std::vector<int> LensIndices(ParameterGroup group) {
    std::vector<int> indices;
    for (int k = 0; k < Model::LensType::kNumParams; ++k)
      if (Model::LensType::kFields[k].group == group) indices.push_back(k);
    return indices;
  }

 private:
  Model base_;
};

}  // namespace omnical
