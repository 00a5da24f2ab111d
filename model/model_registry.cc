#include "model/model_registry.h"

namespace omnical {
namespace {

// Each profile or lens once, in registry order (the variant repeats them per lens).
template <typename Name>
void AddOnce(std::vector<std::string>* names, const Name& name) {
  for (const std::string& n : *names)
    if (n == name) return;
  names->push_back(name);
}

}  // namespace

std::vector<std::string> ProfileNames(bool with_tabulated) {
  std::vector<std::string> names;
  ForEachModelType([&](auto tag) {
    using Profile = typename decltype(tag)::type::ProfileType;
    if (with_tabulated || kFittedProfile<Profile>) AddOnce(&names, Profile::kName);
  });
  return names;
}

std::vector<std::string> DesignProfileNames() {
  std::vector<std::string> names;
  ForEachModelType([&](auto tag) {
    using Profile = typename decltype(tag)::type::ProfileType;
    if (Profile::kRimSlopeParam >= 0) AddOnce(&names, Profile::kName);
  });
  return names;
}

std::string DesignTermsHelp() {
  std::vector<std::string> lists;
  ForEachModelType([&](auto tag) {
    using Profile = typename decltype(tag)::type::ProfileType;
    if constexpr (Profile::kRimSlopeParam >= 0 && Profile::kFields.size() > 0) {
      const ParameterField& last = Profile::kFields.back();
      if (!last.is_list()) return;
      AddOnce(&lists, std::string(Profile::kName) + " " + std::to_string(last.min_count) + "-" +
                          std::to_string(last.max_count) + " (" + last.TermName(0) + ", " + last.TermName(1) + ", ...)");
    }
  });
  return JoinChoices(lists);
}

std::vector<std::string> LensNames() {
  std::vector<std::string> names;
  ForEachModelType([&](auto tag) { AddOnce(&names, decltype(tag)::type::LensType::kName); });
  return names;
}

std::string JoinChoices(const std::vector<std::string>& names) {
  std::string joined;
  for (size_t k = 0; k < names.size(); ++k) joined += (k ? (k + 1 == names.size() ? " or " : ", ") : "") + names[k];
  return joined;
}

}  // namespace omnical
