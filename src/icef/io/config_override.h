// One `--set SECTION.KEY=VALUE` config override, parsed once for every command that takes them
// (`icef train`, `icef bench`: RunConfig::ApplyOverride; `icef render`, `icef eval`: the
// inference-only model keys of model/trained_model.h).
#pragma once

#include <string>

#include "icef/core/status.h"
#include "icef/io/json_util.h"

namespace icef {

struct ConfigOverride {
  std::string section;  // "train" in "train.steps=500"
  std::string key;      // "steps"; a key inside blocks is a dotted path, "static_field.grid.num_levels"
  Json value;           // 500: VALUE parsed as JSON, or the text as a string when it is not valid JSON

  // {"static_field": {"grid": {"num_levels": VALUE}}}: the section's keys this override sets.
  Json SectionPatch() const;
};

// "SECTION.KEY=VALUE" -> its parts; anything else is an error quoting `assignment`.
Result<ConfigOverride> ParseConfigOverride(const std::string& assignment);

}  // namespace icef
