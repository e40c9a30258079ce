// A logging sink passed explicitly (no global logger). Messages at or above the level are written
// to the stream with a level prefix.
#pragma once

#include <ostream>
#include <string>

namespace icef {

enum class LogLevel { kDebug = 0, kInfo = 1, kWarning = 2, kError = 3, kQuiet = 4 };

class Logger {
 public:
  Logger(std::ostream& out, LogLevel level = LogLevel::kInfo) : out_(&out), level_(level) {}
  void Debug(const std::string& m) const { Write(LogLevel::kDebug, m); }
  void Info(const std::string& m) const { Write(LogLevel::kInfo, m); }
  void Warning(const std::string& m) const { Write(LogLevel::kWarning, m); }
  void Error(const std::string& m) const { Write(LogLevel::kError, m); }
  LogLevel level() const { return level_; }

 private:
  void Write(LogLevel level, const std::string& message) const;
  std::ostream* out_;
  LogLevel level_;
};

}  // namespace icef
