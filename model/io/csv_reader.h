// Numeric CSV input for user files (point lists, pixel lists, profile tables).
#pragma once

#include <string>
#include <vector>

namespace omnical {

struct CsvTable {
  std::vector<std::vector<double>> rows;
  std::vector<int> line_numbers;  // 1-based source line of each row, for messages
};

// Reads rows of at least min_columns finite numbers separated by commas (spaces and
// tabs around fields are ignored). Lines before the first numeric row are headers;
// '#' starts a comment; blank lines are skipped. Any later non-numeric, NaN or
// infinite field throws InputError "path:line: column k: ...". An empty table throws.
CsvTable ReadNumericCsv(const std::string& path, int min_columns);

}  // namespace omnical
