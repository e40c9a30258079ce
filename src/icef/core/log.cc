#include "icef/core/log.h"

namespace icef {

void Logger::Write(LogLevel level, const std::string& message) const {
  if (level < level_) return;
  static const char* const kPrefix[] = {"debug: ", "", "warning: ", "error: "};
  *out_ << kPrefix[static_cast<int>(level)] << message << '\n' << std::flush;
}

}  // namespace icef
