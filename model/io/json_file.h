// A JSON file read with omnical's one-line errors (missing, a directory, malformed).
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace omnical {

// Throws InputError "path: problem".
nlohmann::json ReadJsonFile(const std::string& path);

}  // namespace omnical
