// One source of every default: a run config with no keys builds each component with exactly the
// defaults of its own Options struct, and docs/config.md lists those defaults.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "icef/train/train_config.h"

namespace icef {
namespace {

RunConfig EmptyConfig() {
  Result<RunConfig> config = RunConfig::FromJson(Json::object(), "empty");
  ICEF_CHECK(config.ok(), config.status().message());
  return std::move(config).value();
}

TEST(ConfigDefaultsTest, EmptyConfigBuildsEveryComponentWithItsOwnDefaults) {
  const RunConfig config = EmptyConfig();
  const ModelConfig& m = config.model;
  ASSERT_TRUE(config.Validate().ok());
  // icef-prior (the default method) feeds no expression into the static field.
  EXPECT_EQ(m.StaticOptions(11), StaticFieldOptions{})
      << m.StaticOptions(11).ToString() << " vs " << StaticFieldOptions{}.ToString();
  EXPECT_EQ(m.DeformationOptions(), DeformationFieldOptions{}) << m.DeformationOptions().ToString();
  EXPECT_EQ(m.region_mask, RegionMaskOptions{}) << m.region_mask.ToString();
  EXPECT_EQ(m.confidence, ConfidenceOptions{});
  EXPECT_EQ(m.SamplerOptions(true), RaySamplerOptions{}) << m.SamplerOptions(true).ToString();
  EXPECT_EQ(m.occupancy, OccupancyGridOptions{}) << m.occupancy.ToString();
  EXPECT_EQ(m.compositing, CompositeOptions{});
  EXPECT_EQ(m.render, ImageRenderOptions{});
  EXPECT_EQ(m.visual_hull, VisualHullConfig{});
  // The loss terms' settings (their lambdas are TrainConfig's alone: LossWeights{} has every term off).
  const LossWeights w = config.train.Losses(true), d;
  EXPECT_EQ(w.smooth_epsilon, d.smooth_epsilon);
  EXPECT_EQ(w.smooth_max_samples, d.smooth_max_samples);
  EXPECT_EQ(w.symmetry_colour, d.symmetry_colour);
  EXPECT_EQ(w.symmetry_max_samples, d.symmetry_max_samples);
  EXPECT_EQ(w.lambda_id, config.train.lambda_id);
  EXPECT_EQ(w.lambda_id_prior, config.train.lambda_id_prior);
  EXPECT_EQ(w.lambda_occlusion, config.train.lambda_occlusion);
  EXPECT_EQ(w.lambda_occlusion_prior, config.train.lambda_occlusion_prior);
  EXPECT_EQ(w.occlusion_prior_in_regions, config.train.occlusion_prior_in_regions);
  EXPECT_EQ(config.train.Losses(false).lambda_mask, 0.0);
}

// Each block of the model config is its component's Options struct: setting a key inside a block
// through a file or --set reaches exactly that field, and the other fields keep their defaults.
TEST(ConfigDefaultsTest, NestedBlocksMapOntoTheComponentsOptions) {
  Result<RunConfig> config = RunConfig::FromJson(
      Json::parse(R"({"model": {"static_field": {"grid": {"finest_resolution": 256}, "sh_degree": 3},
                                "occupancy": {"threshold": 0.25}, "render": {"supersample": 2}}})"),
      "nested");
  ASSERT_TRUE(config.ok()) << config.status().message();
  StaticFieldOptions expected_static;
  expected_static.grid.finest_resolution = 256;
  expected_static.sh_degree = 3;
  EXPECT_EQ(config->model.StaticOptions(11), expected_static);
  OccupancyGridOptions expected_occupancy;
  expected_occupancy.threshold = 0.25f;
  EXPECT_EQ(config->model.occupancy, expected_occupancy);
  EXPECT_EQ(config->model.render.supersample, 2);
  EXPECT_EQ(config->model.deformation, DeformationFieldOptions{});

  ASSERT_TRUE(config->ApplyOverride("model.static_field.grid.num_levels=12").ok());
  EXPECT_EQ(config->model.static_field.grid.num_levels, 12);
  EXPECT_EQ(config->model.static_field.grid.finest_resolution, 256);  // the block's other keys stay
  // Written back nested, and read back the same.
  const Json written = config->ToJson();
  EXPECT_EQ(written["model"]["static_field"]["grid"]["num_levels"], 12);
  Result<RunConfig> again = RunConfig::FromJson(written, "written");
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_EQ(again->ToJson(), written);
}

// Configs stored before the blocks (checkpoints) used flat keys: they are read into the blocks; a
// user's config or --set with one is an error naming the current key.
TEST(ConfigDefaultsTest, FlatKeysOfEarlierVersionsLoadFromCheckpointsOnly) {
  const Json flat = Json::parse(R"({"model": {"grid_finest_resolution": 256, "visual_hull": false,
      "samples_per_ray": 24, "render_supersample": 2, "kappa_lambda": 0.3, "deform_hidden": [32, 32]}})");
  Result<RunConfig> stored = RunConfig::FromJson(flat, "checkpoint", ConfigSchema::OldKeys::kRead);
  ASSERT_TRUE(stored.ok()) << stored.status().message();
  EXPECT_EQ(stored->model.static_field.grid.finest_resolution, 256);
  EXPECT_FALSE(stored->model.visual_hull.enabled);
  EXPECT_EQ(stored->model.sampler.num_samples, 24);
  EXPECT_EQ(stored->model.render.supersample, 2);
  EXPECT_EQ(stored->model.confidence.lambda, 0.3);
  EXPECT_EQ(stored->model.deformation.hidden, (std::vector<int>{32, 32}));

  const Status user = RunConfig::FromJson(flat, "my.json").status();
  ASSERT_FALSE(user.ok());
  EXPECT_NE(
      user.message().find(
          "my.json: model.grid_finest_resolution: renamed to model.static_field.grid.finest_resolution"),
      std::string::npos)
      << user.message();
  RunConfig config;
  const Status set = config.ApplyOverride("model.samples_per_ray=24");
  EXPECT_NE(set.message().find("renamed to model.sampler.num_samples"), std::string::npos) << set.message();
  // Both spellings at once is ambiguous, even in a stored config.
  const Json both = Json::parse(R"({"model": {"sh_degree": 3, "static_field": {"sh_degree": 4}}})");
  const Status twice = RunConfig::FromJson(both, "checkpoint", ConfigSchema::OldKeys::kRead).status();
  EXPECT_NE(twice.message().find("given twice"), std::string::npos) << twice.message();
}

// docs/config.md holds the table generated from the defaults (tests/integration/config_test.sh
// checks the whole file against `icef config --markdown`).
TEST(ConfigDefaultsTest, DocumentedDefaultsAreTheGeneratedOnes) {
  std::ifstream in(std::string(ICEF_SOURCE_DIR) + "/docs/config.md");
  ASSERT_TRUE(in.good()) << "docs/config.md missing";
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find(ConfigDocumentation()), std::string::npos)
      << "docs/config.md is out of date: regenerate with build/icef config --markdown > docs/config.md";
}

}  // namespace
}  // namespace icef
