// What a lens or profile parameter is, for everything generic over the model registry
// (model/model_registry.h): the sensor file reads and writes it by its key, the bundle fit
// names it, groups it into blocks and holds it by group, the covariance warnings judge it
// by its group, the design fit scales it to mm by its length power.
#pragma once

#include <string>

namespace omnical {

// Which refine switch of the bundle fit a parameter answers to (calib/bundle_fit.h).
enum class ParameterGroup { kFocal, kPrincipalPoint, kDistortion, kTangential, kMirrorDistance, kTilt, kDecenter, kShape };

// How the sensor file checks a value: > 0 and <= bound, or |value| <= bound.
enum class FieldDomain { kPositive, kBounded };

// One field of a lens or profile: a scalar (max_count 1) or a list of numbered terms
// (the even polynomial's c1..cn, the asphere's a4, a6, ...). Only a profile's last field
// may be a list of variable length.
struct ParameterField {
  const char* key = "";   // in the sensor file's camera or mirror section
  const char* name = "";  // in the fit, with its unit (fx_px, A_mm); a list's prefix (c, a)
  ParameterGroup group = ParameterGroup::kShape;
  // Trades with the overall scale: the lens focal length, m and the mirror's size move
  // together along the "dolly zoom" valley the calibration warns about.
  bool scale_like = false;
  FieldDomain domain = FieldDomain::kBounded;
  double bound = 0.0;
  bool optional = false;  // a scalar absent from the sensor file is 0
  bool omitted_when_zero = false;  // an optional scalar the sensor file leaves out when 0
  int min_count = 1, max_count = 1;
  int first_number = 0, number_step = 0;  // a list's names: name + (first + k step)
  // A value in mm^p, p = length_power + k length_power_step: the design fit's normalised
  // units (mirror radius 1) scale by rim^p.
  int length_power = 0, length_power_step = 0;
  // A free-form term: bends the radial mapping as the lens's radial distortion does.
  bool free_form = false;

  bool is_list() const { return max_count > 1 || min_count != 1; }
  std::string TermName(int k) const { return is_list() ? name + std::to_string(first_number + k * number_step) : name; }
  int TermLengthPower(int k) const { return length_power + k * length_power_step; }
};

// A scalar field: key in the file, name in the fit, group, how it is read, its length power.
constexpr ParameterField ScalarField(const char* key, const char* name, ParameterGroup group, bool scale_like,
                                     FieldDomain domain, double bound, int length_power = 0, bool optional = false) {
  ParameterField field{};
  field.key = key, field.name = name, field.group = group, field.scale_like = scale_like;
  field.domain = domain, field.bound = bound;
  field.length_power = length_power;
  field.optional = optional;
  return field;
}

// An optional scalar the sensor file leaves out when it is 0.
constexpr ParameterField OmittedWhenZero(ParameterField field) {
  field.omitted_when_zero = true;
  return field;
}

// A list of numbered shape terms (free-form: they bend the radial mapping).
constexpr ParameterField TermList(const char* key, const char* prefix, int min_count, int max_count, int first_number,
                                  int number_step, int length_power, int length_power_step, double bound,
                                  bool scale_like) {
  ParameterField field{};
  field.key = key, field.name = prefix, field.group = ParameterGroup::kShape, field.scale_like = scale_like;
  field.domain = FieldDomain::kBounded, field.bound = bound;
  field.min_count = min_count;
  field.max_count = max_count;
  field.first_number = first_number;
  field.number_step = number_step;
  field.length_power = length_power;
  field.length_power_step = length_power_step;
  field.free_form = true;
  return field;
}

// One parameter of a concrete sensor, as the fit and its reports name it.
struct ParameterInfo {
  std::string name;  // with its unit: fx_px, m_mm, tilt_x_deg, A_mm, c2, ...
  ParameterGroup group;
  bool scale_like;
  bool free_form;
};

}  // namespace omnical
