#include "icef/app/bench_app.h"

namespace icef {

Status BenchAppOptions::Validate() const {
  ICEF_ASSIGN_OR_RETURN(const eval::BenchOptions resolved, ResolveBenchOptions(*this));
  return resolved.Validate();
}

Result<eval::BenchOptions> ResolveBenchOptions(const BenchAppOptions& a) {
  eval::BenchOptions o = a.base;
  if (a.identities) o.identities = *a.identities;
  if (a.first_seed) o.first_identity_seed = *a.first_seed;
  if (a.resolution) o.resolution = *a.resolution;
  if (a.test_views) o.test_views = *a.test_views;
  if (a.novel_per_tier) o.novel_per_tier = *a.novel_per_tier;
  if (a.steps) o.steps = *a.steps;
  if (a.time_budget) o.time_budget_seconds = *a.time_budget;
  if (a.validation) {
    o.ApplyValidation();
    // Options given explicitly win over the validation settings.
    if (a.identities) o.identities = *a.identities;
    if (a.first_seed) o.first_identity_seed = *a.first_seed;
    if (a.resolution) o.draw_resolution = false;
    if (a.steps) o.steps = *a.steps;
    if (a.time_budget) o.time_budget_seconds = *a.time_budget;
  }
  if (a.quick) {
    const std::vector<std::string> user = o.overrides;
    o.overrides.clear();
    o.ApplyQuick();
    if (o.validation) o.methods = {"icef", "icef-prior"}, o.ks = {5};  // the validation suite, tiny
    // Options given explicitly win over the quick settings.
    if (a.identities) o.identities = *a.identities;
    if (a.resolution) o.resolution = *a.resolution;
    o.draw_resolution = false;  // quick: always the tiny resolution
    if (a.test_views) o.test_views = *a.test_views;
    if (a.novel_per_tier) o.novel_per_tier = *a.novel_per_tier;
    if (a.steps) o.steps = *a.steps;
    if (a.time_budget) o.time_budget_seconds = *a.time_budget;
    o.overrides.insert(o.overrides.end(), user.begin(), user.end());
  }
  // --steps alone is a pure step budget (reproducible); the default caps steps by time.
  if (a.steps && !a.time_budget) o.time_budget_seconds = 0;
  o.out_dir = a.out;
  if (!a.ks.empty()) {
    ICEF_ASSIGN_OR_RETURN(o.ks, eval::ParseIntList(a.ks, "--k"));
  }
  if (!a.methods.empty()) o.methods = a.methods;
  if (!a.shard.empty()) ICEF_RETURN_IF_ERROR(eval::ParseShard(a.shard, &o.shard_index, &o.shard_count));
  return o;
}

Status RunBench(const BenchAppOptions& a, std::ostream& out) {
  ICEF_ASSIGN_OR_RETURN(const eval::BenchOptions options, ResolveBenchOptions(a));
  return eval::RunBench(options, out, a.interactive);
}

}  // namespace icef
