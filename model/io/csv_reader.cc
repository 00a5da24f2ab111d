#include "model/io/csv_reader.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "model/input_error.h"

namespace omnical {
namespace {

std::string Trim(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  const auto last = text.find_last_not_of(" \t\r");
  return text.substr(first, last - first + 1);
}

std::vector<std::string> SplitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream stream(line);
  std::string field;
  while (std::getline(stream, field, ',')) fields.push_back(Trim(field));
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

// Parses a whole field as a double; false for text, empty fields or trailing junk.
bool ParseNumber(const std::string& field, double* value) {
  if (field.empty()) return false;
  char* end = nullptr;
  errno = 0;
  *value = std::strtod(field.c_str(), &end);
  return end == field.c_str() + field.size() && errno != ERANGE;
}

}  // namespace

CsvTable ReadNumericCsv(const std::string& path, int min_columns) {
  std::ifstream file(path);
  if (!file) throw InputError(InputMessage(path, "", "cannot open file"));
  CsvTable table;
  std::string line;
  int line_number = 0;
  while (std::getline(file, line)) {
    ++line_number;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    if (Trim(line).empty()) continue;
    const std::vector<std::string> fields = SplitFields(line);
    std::vector<double> row;
    int bad_column = -1;
    for (size_t k = 0; k < fields.size(); ++k) {
      double value = 0.0;
      if (!ParseNumber(fields[k], &value)) {
        bad_column = static_cast<int>(k);
        break;
      }
      row.push_back(value);
    }
    const std::string where = path + ":" + std::to_string(line_number);
    if (bad_column >= 0) {
      if (table.rows.empty() && bad_column == 0) continue;  // header line
      throw InputError(where + ": column " + std::to_string(bad_column + 1) + ": '" +
                       fields[bad_column] + "' is not a number");
    }
    for (size_t k = 0; k < row.size(); ++k)
      if (!std::isfinite(row[k]))
        throw InputError(where + ": column " + std::to_string(k + 1) + ": value is not finite");
    if (static_cast<int>(row.size()) < min_columns)
      throw InputError(where + ": expected at least " + std::to_string(min_columns) +
                       " columns, found " + std::to_string(row.size()));
    table.rows.push_back(std::move(row));
    table.line_numbers.push_back(line_number);
  }
  if (file.bad()) throw InputError(InputMessage(path, "", "read error"));
  if (table.rows.empty()) throw InputError(InputMessage(path, "", "no numeric rows"));
  return table;
}

}  // namespace omnical
