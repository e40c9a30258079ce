// Number checks for command-line options whose messages state the rule. CLI11's own
// NonNegativeNumber and PositiveNumber print their range's upper bound to 300 digits and call 0
// "not in range 0 to ...".
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdlib>
#include <string>

namespace icef::cli {

namespace internal {
inline CLI::Validator NumberCheck(bool allow_zero) {
  const std::string name = allow_zero ? "NONNEGATIVE" : "POSITIVE";
  return CLI::Validator(
      [allow_zero](std::string& value) -> std::string {
        char* end = nullptr;
        const double number = std::strtod(value.c_str(), &end);
        const bool parsed = !value.empty() && end != nullptr && *end == '\0' && std::isfinite(number);
        const std::string rule = allow_zero ? "a number >= 0" : "a number > 0";
        if (!parsed || number < 0.0 || (!allow_zero && number == 0.0))
          return "must be " + rule + ", got '" + value + "'";
        return "";
      },
      name, name);
}
}  // namespace internal

inline const CLI::Validator kNonNegative = internal::NumberCheck(true);
inline const CLI::Validator kPositive = internal::NumberCheck(false);

}  // namespace icef::cli
