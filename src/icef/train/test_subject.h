// For the train/ tests only: a small synthetic head (16x16 RGBA images, 3 training frames, 68
// landmarks on every frame), synthesised once per test binary and name.
#pragma once

#include <map>
#include <string>
#include <utility>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/data/dataset.h"
#include "icef/synth/synthesize.h"
#include "icef/testing/tiny_dataset.h"

namespace icef::testing {

inline const Dataset& TinySubject(const std::string& name) {
  static std::map<std::string, Dataset>* subjects = new std::map<std::string, Dataset>;
  const auto it = subjects->find(name);
  if (it != subjects->end()) return it->second;
  synth::SynthOptions o;
  o.out_dir = MakeTempDir(name);
  o.num_train = 3;
  o.resolution = 16;
  o.test_views = 1;
  o.novel_per_tier = 1;
  ICEF_CHECK(synth::SynthesizeDataset(o, Executor(1)).ok());
  Result<Dataset> loaded = LoadDataset(o.out_dir);
  ICEF_CHECK(loaded.ok(), loaded.status().message());
  return subjects->emplace(name, std::move(loaded).value()).first->second;
}

}  // namespace icef::testing
