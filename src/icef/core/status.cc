#include "icef/core/status.h"

namespace icef {

const std::string& Status::message() const {
  static const std::string kOk = "OK";
  return message_ ? *message_ : kOk;
}

Status Status::WithContext(const std::string& prefix) const {
  if (ok()) return *this;
  return Status::Error(prefix + ": " + *message_);
}

void ThrowCheckFailure(const char* file, int line, const char* condition, const std::string& message) {
  std::string what = std::string(file) + ":" + std::to_string(line) + ": check failed: " + condition;
  if (!message.empty()) what += ": " + message;
  throw InternalError(what);
}

}  // namespace icef
