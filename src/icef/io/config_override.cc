#include "icef/io/config_override.h"

#include <vector>

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

Json ConfigOverride::SectionPatch() const {
  std::vector<std::string> parts;
  for (size_t start = 0;;) {
    const size_t dot = key.find('.', start);
    parts.push_back(key.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  Json patch = value;
  for (auto part = parts.rbegin(); part != parts.rend(); ++part) {
    Json outer;
    outer[*part] = std::move(patch);
    patch = std::move(outer);
  }
  return patch;
}

}  // namespace icef
