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
  EXPECT_EQ(m.StaticOptions(11), StaticFieldOptions{}) << m.StaticOptions(11).ToString() << " vs "
                                                        << StaticFieldOptions{}.ToString();
  EXPECT_EQ(m.DeformationOptions(), DeformationFieldOptions{}) << m.DeformationOptions().ToString();
  EXPECT_EQ(m.MaskOptions(), RegionMaskOptions{}) << m.MaskOptions().ToString();
  EXPECT_EQ(m.ConfidenceOpts(), ConfidenceOptions{});
  EXPECT_EQ(m.SamplerOptions(true), RaySamplerOptions{}) << m.SamplerOptions(true).ToString();
  EXPECT_EQ(m.OccupancyOptions(), OccupancyGridOptions{}) << m.OccupancyOptions().ToString();
  EXPECT_EQ(m.CompositeOpts(), CompositeOptions{});
  // The loss terms' settings (their lambdas are TrainConfig's alone: LossWeights{} has every term off).
  const LossWeights w = config.train.Losses(true), d;
  EXPECT_EQ(w.smooth_epsilon, d.smooth_epsilon);
  EXPECT_EQ(w.smooth_max_samples, d.smooth_max_samples);
  EXPECT_EQ(w.symmetry_colour, d.symmetry_colour);
  EXPECT_EQ(w.symmetry_max_samples, d.symmetry_max_samples);
  EXPECT_EQ(w.lambda_id, config.train.lambda_id);
  EXPECT_EQ(config.train.Losses(false).lambda_mask, 0.0);
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
