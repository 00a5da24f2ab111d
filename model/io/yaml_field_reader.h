// Reading user YAML files (sensor, target, scene) with one error policy: every problem is
// an InputError "file: field: problem" on one line, unknown keys included (a misspelt
// optional key would otherwise be silently ignored). Internal to omnical's readers.
#pragma once

#include <yaml-cpp/yaml.h>

#include <set>
#include <string>
#include <utility>
#include <vector>

namespace omnical {

class YamlFieldReader {
 public:
  explicit YamlFieldReader(std::string path) : path_(std::move(path)) {}

  // The file's root node; missing files and malformed YAML become InputErrors.
  YAML::Node LoadFile() const;

  [[noreturn]] void Fail(const std::string& field, const std::string& problem) const;

  // `where` prefixes the keys in messages ("camera" -> "camera.fx"); empty for the root.
  void RejectUnknown(const YAML::Node& map, const std::string& where, const std::set<std::string>& known) const;
  YAML::Node Section(const YAML::Node& root, const std::string& name) const;  // a required map

  // A finite number; `field` is the full name used in messages.
  double Number(const YAML::Node& node, const std::string& field) const;
  double NumberOr(const YAML::Node& map, const std::string& key, const std::string& where, double fallback) const;
  // Strictly positive and at most max_value.
  double Positive(const YAML::Node& node, const std::string& field, double max_value) const;
  // |value| <= limit.
  double Bounded(const YAML::Node& node, const std::string& field, double limit) const;
  std::vector<double> Numbers(const YAML::Node& node, const std::string& field, size_t min_count, size_t max_count) const;
  // [low, high] with low <= high, or the fallback when the key is absent.
  std::pair<double, double> Range(const YAML::Node& map, const std::string& key, const std::string& where,
                                  std::pair<double, double> fallback) const;
  std::string Text(const YAML::Node& node, const std::string& field) const;
  // A path written in the file, relative to the file's directory.
  std::string Resolve(const std::string& relative) const;

  static std::string Join(const std::string& where, const std::string& key) { return where.empty() ? key : where + "." + key; }
  static std::string Format(double value);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace omnical
