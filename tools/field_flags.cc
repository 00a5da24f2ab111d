#include "tools/field_flags.h"

#include <algorithm>

namespace omnical::cli {

FlagTable FlagsOf(std::initializer_list<const char*> fields, const FlagTable& renamed) {
  FlagTable table = renamed;
  for (const char* field : fields) {
    std::string flag = std::string("--") + field;
    std::replace(flag.begin(), flag.end(), '_', '-');
    table[field] = flag;
  }
  return table;
}

std::string FlagMessage(const std::string& message, const FlagTable& flags) {
  const size_t colon = message.find(": ");
  if (colon == std::string::npos) return message;
  std::string named;
  for (size_t start = 0; start <= colon;) {
    const size_t slash = std::min(message.find('/', start), colon);
    const auto flag = flags.find(message.substr(start, slash - start));
    if (flag == flags.end()) return message;
    named += (named.empty() ? "" : "/") + flag->second;
    start = slash + 1;
  }
  return named + message.substr(colon);
}

}  // namespace omnical::cli
