#include "model/io/json_file.h"

#include <filesystem>
#include <fstream>

#include "model/input_error.h"

namespace omnical {

nlohmann::json ReadJsonFile(const std::string& path) {
  // A directory opens as a stream, then throws std::ios_failure inside the parser.
  if (std::filesystem::is_directory(path)) throw InputError(InputMessage(path, "", "is a directory, not a file"));
  std::ifstream file(path);
  if (!file) throw InputError(InputMessage(path, "", std::filesystem::exists(path) ? "cannot read" : "file not found"));
  try {
    return nlohmann::json::parse(file);
  } catch (const nlohmann::json::exception& error) {
    throw InputError(InputMessage(path, "", std::string("malformed JSON: ") + error.what()));
  } catch (const std::exception& error) {
    throw InputError(InputMessage(path, "", std::string("cannot read: ") + error.what()));
  }
}

}  // namespace omnical
