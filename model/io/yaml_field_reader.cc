#include "model/io/yaml_field_reader.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include "model/input_error.h"

namespace omnical {

YAML::Node YamlFieldReader::LoadFile() const {
  if (!std::filesystem::exists(path_)) Fail("", "file not found");
  // A directory opens as a stream and then throws std::ios_failure from inside yaml-cpp
  // (found by tests/fuzz: a scene naming "sensor: ..").
  if (std::filesystem::is_directory(path_)) Fail("", "is a directory, not a file");
  try {
    return YAML::LoadFile(path_);
  } catch (const YAML::ParserException& error) {
    Fail("line " + std::to_string(error.mark.line + 1), "malformed YAML: " + error.msg);
  } catch (const YAML::Exception& error) {
    Fail("", std::string("cannot read: ") + error.what());
  } catch (const std::exception& error) {
    Fail("", std::string("cannot read: ") + error.what());
  }
}

void YamlFieldReader::Fail(const std::string& field, const std::string& problem) const {
  throw InputError(InputMessage(path_, field, problem));
}

void YamlFieldReader::RejectUnknown(const YAML::Node& map, const std::string& where,
                                    const std::set<std::string>& known) const {
  if (!map.IsMap()) Fail(where.empty() ? "(top level)" : where, "must be a map of fields");
  for (const auto& entry : map) {
    // A complex key ("? [a, b]: ..." or "? :") is no field name; as<string> would throw
    // yaml-cpp's own exception (found by the fuzzer).
    if (!entry.first.IsScalar()) Fail(where.empty() ? "(top level)" : where, "has a key that is not a plain field name");
    const std::string key = entry.first.as<std::string>();
    if (!known.count(key)) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      Fail(Join(where, key), "unknown field (expected one of: " + list + ")");
    }
  }
}

YAML::Node YamlFieldReader::Section(const YAML::Node& root, const std::string& name) const {
  const YAML::Node node = root[name];
  if (!node) Fail(name, "missing section");
  if (!node.IsMap()) Fail(name, "must be a map of fields");
  return node;
}

double YamlFieldReader::Number(const YAML::Node& node, const std::string& field) const {
  if (!node) Fail(field, "missing");
  if (!node.IsScalar()) Fail(field, "must be a number");
  double value = 0.0;
  try {
    value = node.as<double>();
  } catch (const YAML::Exception&) {
    Fail(field, "'" + node.Scalar() + "' is not a number");
  }
  if (!std::isfinite(value)) Fail(field, "must be finite");
  return value;
}

double YamlFieldReader::NumberOr(const YAML::Node& map, const std::string& key, const std::string& where,
                                 double fallback) const {
  return map[key] ? Number(map[key], Join(where, key)) : fallback;
}

double YamlFieldReader::Positive(const YAML::Node& node, const std::string& field, double max_value) const {
  const double value = Number(node, field);
  if (!(value > 0.0)) Fail(field, "must be > 0 (got " + Format(value) + ")");
  if (!(value <= max_value)) Fail(field, "must be <= " + Format(max_value) + " (got " + Format(value) + ")");
  return value;
}

double YamlFieldReader::Bounded(const YAML::Node& node, const std::string& field, double limit) const {
  const double value = Number(node, field);
  if (!(std::abs(value) <= limit)) Fail(field, "magnitude must be <= " + Format(limit) + " (got " + Format(value) + ")");
  return value;
}

std::vector<double> YamlFieldReader::Numbers(const YAML::Node& node, const std::string& field, size_t min_count,
                                             size_t max_count) const {
  if (!node) Fail(field, "missing");
  if (!node.IsSequence()) Fail(field, "must be a list of numbers");
  if (node.size() < min_count || node.size() > max_count) {
    Fail(field, min_count == max_count ? "must list " + std::to_string(min_count) + " numbers"
                                       : "must list " + std::to_string(min_count) + " to " +
                                             std::to_string(max_count) + " numbers");
  }
  std::vector<double> values;
  for (size_t i = 0; i < node.size(); ++i) values.push_back(Number(node[i], field + "[" + std::to_string(i) + "]"));
  return values;
}

std::pair<double, double> YamlFieldReader::Range(const YAML::Node& map, const std::string& key, const std::string& where,
                                                 std::pair<double, double> fallback) const {
  if (!map[key]) return fallback;
  const std::string field = Join(where, key);
  const std::vector<double> values = Numbers(map[key], field, 2, 2);
  if (!(values[0] <= values[1])) Fail(field, "must be [low, high] with low <= high");
  return {values[0], values[1]};
}

std::string YamlFieldReader::Text(const YAML::Node& node, const std::string& field) const {
  if (!node) Fail(field, "missing");
  if (!node.IsScalar()) Fail(field, "must be a string");
  return node.Scalar();
}

std::string YamlFieldReader::Resolve(const std::string& relative) const {
  std::filesystem::path p(relative);
  if (p.is_relative()) p = std::filesystem::path(path_).parent_path() / p;
  return p.lexically_normal().string();
}

std::string YamlFieldReader::Format(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

}  // namespace omnical
