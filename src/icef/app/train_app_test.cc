// The run config of `icef train --resume` (ResolveResumeConfig): the checkpoint's config, changed
// only in the step count, time budget, thread count and on_nonfinite; anything else is refused
// with the keys and both values named.
#include "icef/app/train_app.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

namespace icef {
namespace {

namespace fs = std::filesystem;

// A config as `icef train --config tiny.json` would have trained it.
RunConfig Saved() {
  RunConfig c;
  c.train.steps = 40;
  c.train.lambda_id = 0.2;
  c.train.threads = 2;
  return c;
}

fs::path WriteConfigFile(const std::string& name, const std::string& text) {
  const fs::path dir = fs::temp_directory_path() / ("icef_train_app_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / name) << text;
  return dir / name;
}

TEST(ResumeConfig, NoOptionsKeepTheCheckpointConfig) {
  const Result<RunConfig> c = ResolveResumeConfig(TrainAppOptions{}, Saved(), "m/checkpoint.icef");
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->ToJson(), Saved().ToJson());
}

TEST(ResumeConfig, BudgetThreadsAndNonFinitePolicyMayChange) {
  TrainAppOptions o;
  o.steps = 120;
  o.time_budget = 30;
  o.threads = 1;
  o.overrides = {"train.on_nonfinite=skip"};
  const Result<RunConfig> c = ResolveResumeConfig(o, Saved(), "m/checkpoint.icef");
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->train.steps, 120);
  EXPECT_EQ(c->train.time_budget_seconds, 30);
  EXPECT_EQ(c->train.threads, 1);
  EXPECT_EQ(c->train.on_nonfinite, "skip");
  EXPECT_EQ(c->train.lambda_id, 0.2);
}

TEST(ResumeConfig, OtherChangesAreRefusedNamingEachKey) {
  TrainAppOptions o;
  o.overrides = {"train.lambda_id=0.5", "train.steps=99"};
  o.method = "warp";
  const Status s = ResolveResumeConfig(o, Saved(), "m/checkpoint.icef").status();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("m/checkpoint.icef: cannot resume with a different run config"),
            std::string::npos)
      << s.message();
  EXPECT_NE(s.message().find("model.method (checkpoint \"icef-prior\", given \"warp\")"), std::string::npos)
      << s.message();
  EXPECT_NE(s.message().find("train.lambda_id (checkpoint 0.2, given 0.5)"), std::string::npos)
      << s.message();
  EXPECT_EQ(s.message().find("train.steps ("), std::string::npos) << "steps may change: " << s.message();
}

TEST(ResumeConfig, ConfigFileIsAWholeRunConfig) {
  // The same file as the original run: accepted (its step count applies).
  TrainAppOptions same;
  same.config_file =
      WriteConfigFile("same.json", R"({"train": {"steps": 60, "lambda_id": 0.2, "threads": 2}})");
  const Result<RunConfig> c = ResolveResumeConfig(same, Saved(), "m/checkpoint.icef");
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->train.steps, 60);
  // A file that leaves lambda_id at its default describes a different run.
  TrainAppOptions other;
  other.config_file = WriteConfigFile("other.json", R"({"train": {"steps": 40}})");
  const Status s = ResolveResumeConfig(other, Saved(), "m/checkpoint.icef").status();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("other.json"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("train.lambda_id (checkpoint 0.2, given 1.0)"), std::string::npos)
      << s.message();
  fs::remove_all(other.config_file->parent_path());
}

}  // namespace
}  // namespace icef
