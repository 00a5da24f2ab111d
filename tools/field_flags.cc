#include "tools/field_flags.h"

#include <algorithm>
#include <cctype>

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

std::string FlagWords(std::string message, const FlagTable& flags) {
  auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (const auto& [field, flag] : flags) {
    for (size_t at = message.find(field); at != std::string::npos; at = message.find(field, at)) {
      const size_t end = at + field.size();
      if ((at > 0 && (word(message[at - 1]) || message[at - 1] == '-')) || (end < message.size() && word(message[end]))) {
        at = end;
        continue;
      }
      message.replace(at, field.size(), flag);
      at += flag.size();
    }
  }
  return message;
}

}  // namespace omnical::cli
