// The registry of mirror profiles and lenses: the one list from which the sensor variant
// (SensorModel), the sensor file's reader and writer, the fit's parameter packing, names
// and groups, the CLI and Python choices and the design families are all generated.
//
// How to add a mirror profile (model/even_asphere_profile.h is a complete example):
//  1. Write it in its own header, model/<name>_profile.h, with the interface below.
//  2. Add it to RegisteredProfiles here (and include its header).
//  3. Give the model tests a sensor of it (tests/test_sensors.h, which checks that every
//     registered profile has one) and describe its fields in docs/file-formats.md.
// A lens is the same with RegisteredLenses (model/lenses.h).
//
// Profile<T> (T the scalar: double, or a ceres::Jet so derivatives flow through):
//   kName                     the sensor file's mirror.profile and the CLI/Python choice
//   kFields                   its parameters in order (model/parameter_field.h): the sensor
//                             file's key, the fit's name, group, domain, length power
//   kMaxParams, NumParams()   how many (0 for a tabulated profile, never fitted)
//   kRimSlopeParam            the parameter SolveRimSlope sets (-1: not a design family)
//   TiltObservable()          false where a turned mirror is the same surface (a sphere)
//   FromParams(p, count), ToParams(p), WithParams<U>(p)   the parameters as a flat array
//   FromVertexRadius(R, rim)  the family's member nearest a sphere of vertex radius R
//   SolveRimSlope<U>(p, count, slope)   sets kRimSlopeParam so that f'(1) = slope
//   EvaluateSag<S>(r^2), CheckDomain(rim), MaxRadiusMm(), Cast<U>()   the geometry
//                             (model/mirror_profiles.h explains the s = r^2 convention)
//   kSettings, ToSettings(v), SetSettings(v)   optional: values of the sensor file that
//                             shape the profile but are no parameters (the spline's span):
//                             read and written after rim_radius, never fitted, kept by
//                             WithParams and Cast (ProfileSettings below)
// Lens<T>:
//   kName, kFields, kNumParams, kIsOrthographic, FromParams(p), ToParams(p),
//   ProjectToPixel, PixelToRay, MaxFocalPx, CheckDomain, Cast<U>()
#pragma once

#include <array>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "model/catadioptric.h"
#include "model/even_asphere_profile.h"
#include "model/lenses.h"
#include "model/mirror_profiles.h"
#include "model/parameter_field.h"
#include "model/spline_profile.h"
#include "model/tabulated_profile.h"

namespace omnical {

template <template <typename> class... Profiles>
struct ProfileList {};
template <template <typename> class... Lenses>
struct LensList {};

using RegisteredProfiles = ProfileList<SphereProfile, EvenPolynomialProfile, HyperboloidProfile, ParaboloidProfile,
                                       TabulatedProfile, EvenAsphereProfile, SplineProfile>;
using RegisteredLenses = LensList<PinholeLens, OrthographicLens>;

namespace registry_detail {

template <typename... Variants>
struct Concat;
template <typename... A>
struct Concat<std::variant<A...>> {
  using type = std::variant<A...>;
};
template <typename... A, typename... B, typename... Rest>
struct Concat<std::variant<A...>, std::variant<B...>, Rest...> {
  using type = typename Concat<std::variant<A..., B...>, Rest...>::type;
};

template <typename Profiles, template <typename> class Lens>
struct WithLens;
template <template <typename> class... Profiles, template <typename> class Lens>
struct WithLens<ProfileList<Profiles...>, Lens> {
  using type = std::variant<Catadioptric<double, Profiles, Lens>...>;
};

template <typename Profiles, typename Lenses>
struct CrossProduct;
template <typename Profiles, template <typename> class... Lenses>
struct CrossProduct<Profiles, LensList<Lenses...>> {
  using type = typename Concat<typename WithLens<Profiles, Lenses>::type...>::type;
};

template <typename Variant, typename F, size_t... I>
void ForEachAlternative(F&& f, std::index_sequence<I...>);

}  // namespace registry_detail

// Every profile with every lens, lens-major.
using SensorModel = typename registry_detail::CrossProduct<RegisteredProfiles, RegisteredLenses>::type;

template <typename T>
struct TypeTag {
  using type = T;
};

// Calls f(TypeTag<Model>{}) for every model type of the registry.
template <typename F>
void ForEachModelType(F&& f) {
  registry_detail::ForEachAlternative<SensorModel>(f, std::make_index_sequence<std::variant_size_v<SensorModel>>{});
}

template <typename Variant, typename F, size_t... I>
void registry_detail::ForEachAlternative(F&& f, std::index_sequence<I...>) {
  (f(TypeTag<std::variant_alternative_t<I, Variant>>{}), ...);
}

// A profile's parameters: fitted or not, in the order of its fields.
template <typename Profile>
constexpr bool kFittedProfile = Profile::kMaxParams > 0;

// A profile's settings (kSettings): none unless it declares them.
template <typename Profile, typename = void>
struct ProfileSettings {
  static constexpr std::array<ParameterField, 0> kFields{};
};
template <typename Profile>
struct ProfileSettings<Profile, std::void_t<decltype(Profile::kSettings)>> {
  static constexpr auto kFields = Profile::kSettings;
};
template <typename Profile>
constexpr bool kHasSettings = ProfileSettings<Profile>::kFields.size() > 0;

// The profile names, in registry order (with_tabulated: also those the fit cannot shape).
std::vector<std::string> ProfileNames(bool with_tabulated = true);
// The profiles the design fit can shape (they have a kRimSlopeParam).
std::vector<std::string> DesignProfileNames();
std::vector<std::string> LensNames();
// The design profiles' lists of terms, for help texts: "polynomial 1-8 (c1, c2, ...)".
std::string DesignTermsHelp();
// "a, b, c or d", for messages and help texts.
std::string JoinChoices(const std::vector<std::string>& names);

// The number of values in each of a profile's fields for `count` parameters (only the
// last field can be a list of variable length).
template <typename Profile>
std::vector<int> FieldCounts(int count) {
  std::vector<int> counts;
  int left = count;
  for (size_t f = 0; f < Profile::kFields.size(); ++f) {
    const bool last = f + 1 == Profile::kFields.size();
    const int n = last && Profile::kFields[f].is_list() ? left : 1;
    counts.push_back(n);
    left -= n;
  }
  return counts;
}

// Calls each(field, term index k, parameter index) for each of the profile's parameters.
template <typename Profile, typename Each>
void ForEachProfileParameter(int count, const Each& each) {
  const std::vector<int> counts = FieldCounts<Profile>(count);
  int index = 0;
  for (size_t f = 0; f < Profile::kFields.size(); ++f)
    for (int k = 0; k < counts[f]; ++k) each(Profile::kFields[f], k, index++);
}

// The sensor's parameters in the fit's order and naming: the lens's, then m, tilt
// (x, y, reported in deg), decenter (x, y), then the profile's.
template <typename Model>
std::vector<ParameterInfo> SensorParameterInfos(const Model& model) {
  using Lens = typename Model::LensType;
  using Profile = typename Model::ProfileType;
  std::vector<ParameterInfo> infos;
  for (const ParameterField& f : Lens::kFields) infos.push_back({f.name, f.group, f.scale_like, f.free_form});
  infos.push_back({"m_mm", ParameterGroup::kMirrorDistance, true, false});
  infos.push_back({"tilt_x_deg", ParameterGroup::kTilt, false, false});
  infos.push_back({"tilt_y_deg", ParameterGroup::kTilt, false, false});
  infos.push_back({"decenter_x_mm", ParameterGroup::kDecenter, false, false});
  infos.push_back({"decenter_y_mm", ParameterGroup::kDecenter, false, false});
  ForEachProfileParameter<Profile>(model.mirror.NumParams(), [&](const ParameterField& f, int k, int) {
    infos.push_back({f.TermName(k), f.group, f.scale_like, f.free_form});
  });
  return infos;
}

// Whether the profile's shape bends the radial mapping as a lens's radial distortion does
// (free-form terms present): then the two trade off and the fit holds the distortion.
template <typename Profile>
bool HasFreeFormTerms(const Profile& profile) {
  bool any = false;
  ForEachProfileParameter<Profile>(profile.NumParams(), [&](const ParameterField& f, int, int) { any = any || f.free_form; });
  return any;
}

}  // namespace omnical
