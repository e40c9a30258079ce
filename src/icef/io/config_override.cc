#include "icef/io/config_override.h"

namespace icef {

Result<ConfigOverride> ParseConfigOverride(const std::string& assignment) {
  const size_t eq = assignment.find('=');
  const size_t dot = assignment.find('.');
  if (eq == std::string::npos || dot == std::string::npos || dot > eq)
    return Status::Error("--set '" + assignment + "': expected SECTION.KEY=VALUE, e.g. train.steps=500");
  ConfigOverride o;
  o.section = assignment.substr(0, dot);
  o.key = assignment.substr(dot + 1, eq - dot - 1);
  const std::string text = assignment.substr(eq + 1);
  o.value = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (o.value.is_discarded()) o.value = text;
  return o;
}

}  // namespace icef
