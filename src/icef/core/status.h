// Error policy (STYLE.md habit 2):
//  - failures caused by the outside world (files, parsing, user input) are returned as a Status or
//    Result<T> whose message names the file and the field;
//  - broken internal invariants throw icef::InternalError via ICEF_CHECK, with file:line.
// The CLI maps a failed Status to exit code 1 and an InternalError to exit code 2.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>

namespace icef {

class Status {
 public:
  Status() = default;  // OK
  static Status Ok() { return Status(); }
  static Status Error(std::string message) { return Status(std::move(message)); }

  bool ok() const { return !message_.has_value(); }
  explicit operator bool() const { return ok(); }
  const std::string& message() const;
  std::string ToString() const { return ok() ? "OK" : "error: " + *message_; }

  // Returns a copy whose message is "prefix: message" (no-op when OK). Used to add context as an
  // error travels outwards, e.g. WithContext("data/transforms_train.json").
  Status WithContext(const std::string& prefix) const;

 private:
  explicit Status(std::string message) : message_(std::move(message)) {}
  std::optional<std::string> message_;
};

// A value or an error Status.
template <typename T>
class Result {
 public:
  Result(T value) : v_(std::move(value)) {}        // NOLINT: implicit by design
  Result(Status status) : v_(std::move(status)) {  // NOLINT: implicit by design
    if (std::get<Status>(v_).ok()) v_ = Status::Error("internal: Result built from an OK Status");
  }

  bool ok() const { return std::holds_alternative<T>(v_); }
  explicit operator bool() const { return ok(); }
  Status status() const { return ok() ? Status::Ok() : std::get<Status>(v_); }
  const T& value() const&;
  T& value() &;
  T&& value() &&;
  const T& operator*() const& { return value(); }
  T& operator*() & { return value(); }
  const T* operator->() const { return &value(); }
  T* operator->() { return &value(); }

 private:
  std::variant<T, Status> v_;
};

// Thrown for broken invariants (programming errors), never for bad user input.
class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

[[noreturn]] void ThrowCheckFailure(const char* file, int line, const char* condition,
                                    const std::string& message);

template <typename T>
const T& Result<T>::value() const& {
  if (!ok()) ThrowCheckFailure(__FILE__, __LINE__, "ok()", std::get<Status>(v_).message());
  return std::get<T>(v_);
}
template <typename T>
T& Result<T>::value() & {
  if (!ok()) ThrowCheckFailure(__FILE__, __LINE__, "ok()", std::get<Status>(v_).message());
  return std::get<T>(v_);
}
template <typename T>
T&& Result<T>::value() && {
  if (!ok()) ThrowCheckFailure(__FILE__, __LINE__, "ok()", std::get<Status>(v_).message());
  return std::move(std::get<T>(v_));
}

}  // namespace icef

// ICEF_CHECK(cond, "message"): throws icef::InternalError("file:line: check failed: cond: message").
#define ICEF_CHECK(cond, ...)                                                                    \
  do {                                                                                           \
    if (!(cond)) ::icef::ThrowCheckFailure(__FILE__, __LINE__, #cond, std::string{__VA_ARGS__}); \
  } while (0)

// Propagates an error Status out of the current function.
#define ICEF_RETURN_IF_ERROR(expr)               \
  do {                                           \
    ::icef::Status icef_status_ = (expr);        \
    if (!icef_status_.ok()) return icef_status_; \
  } while (0)

#define ICEF_CONCAT_INNER_(a, b) a##b
#define ICEF_CONCAT_(a, b) ICEF_CONCAT_INNER_(a, b)
// ICEF_ASSIGN_OR_RETURN(auto x, ExprReturningResult()); returns the error Status on failure.
#define ICEF_ASSIGN_OR_RETURN(lhs, expr) \
  ICEF_ASSIGN_OR_RETURN_IMPL_(ICEF_CONCAT_(icef_result_, __LINE__), lhs, expr)
#define ICEF_ASSIGN_OR_RETURN_IMPL_(tmp, lhs, expr) \
  auto tmp = (expr);                                \
  if (!tmp.ok()) return tmp.status();               \
  lhs = std::move(tmp).value()
