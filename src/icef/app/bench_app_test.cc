// ResolveBenchOptions: the defaults, then --validation, then --quick, with the options given
// explicitly winning over both; --steps alone drops the time cap.
#include "icef/app/bench_app.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <sstream>

#include "icef/data/dataset.h"
#include "icef/face/ict_model.h"
#include "icef/io/atomic_file.h"
#include "icef/train/train_config.h"

namespace icef {
namespace {

TEST(BenchApp, DefaultsPassThrough) {
  BenchAppOptions a;
  a.out = "b";
  const Result<eval::BenchOptions> o = ResolveBenchOptions(a);
  ASSERT_TRUE(o.ok()) << o.status().message();
  const eval::BenchOptions d;
  EXPECT_EQ(o->out_dir, "b");
  EXPECT_EQ(o->identities, d.identities);
  EXPECT_EQ(o->ks, d.ks);
  EXPECT_EQ(o->steps, d.steps);
  EXPECT_EQ(o->time_budget_seconds, d.time_budget_seconds);
  EXPECT_TRUE(a.Validate().ok()) << a.Validate().message();
}

TEST(BenchApp, QuickSettingsLoseToExplicitOptions) {
  BenchAppOptions a;
  a.out = "b";
  a.quick = true;
  a.resolution = 48;
  a.base.overrides = {"train.lambda_id=0.5"};
  const Result<eval::BenchOptions> o = ResolveBenchOptions(a);
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_EQ(o->identities, 1);
  EXPECT_EQ(o->ks, std::vector<int>{3});
  EXPECT_EQ(o->resolution, 48);  // given
  EXPECT_EQ(o->steps, 20);
  EXPECT_EQ(o->time_budget_seconds, 0);
  ASSERT_FALSE(o->overrides.empty());
  EXPECT_EQ(o->overrides.back(), "train.lambda_id=0.5");  // the user's come after the quick ones
  EXPECT_GT(o->overrides.size(), 1u);
}

TEST(BenchApp, ValidationSettingsLoseToExplicitOptions) {
  BenchAppOptions a;
  a.out = "b";
  a.validation = true;
  a.identities = 2;
  a.ks = "3,10";
  const Result<eval::BenchOptions> o = ResolveBenchOptions(a);
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_TRUE(o->validation);
  EXPECT_EQ(o->identities, 2);
  EXPECT_EQ(o->first_identity_seed, eval::kFirstValidationSeed);
  EXPECT_EQ(o->ks, (std::vector<int>{3, 10}));
  // Diverse scenes with a drawn resolution; the validation methods.
  EXPECT_TRUE(o->diverse);
  EXPECT_TRUE(o->draw_resolution);
  EXPECT_EQ(o->methods, (std::vector<std::string>{"icef", "icef-prior"}));
  EXPECT_EQ(o->time_budget_seconds, 0.0);    // steps only: reproducible
  EXPECT_EQ(o->steps, TrainConfig().steps);  // as `icef train` trains
  // --res pins the resolution; the scenes stay diverse.
  a.resolution = 160;
  const Result<eval::BenchOptions> pinned = ResolveBenchOptions(a);
  ASSERT_TRUE(pinned.ok());
  EXPECT_TRUE(pinned->diverse);
  EXPECT_FALSE(pinned->draw_resolution);
  EXPECT_EQ(pinned->resolution, 160);
}

TEST(BenchApp, QuickValidationIsTheValidationSuiteInMiniature) {
  BenchAppOptions a;
  a.out = "b";
  a.validation = true;
  a.quick = true;
  const Result<eval::BenchOptions> o = ResolveBenchOptions(a);
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_TRUE(o->diverse);
  EXPECT_FALSE(o->draw_resolution);
  EXPECT_EQ(o->resolution, 32);
  EXPECT_EQ(o->identities, 1);
  EXPECT_EQ(o->first_identity_seed, eval::kFirstValidationSeed);
  EXPECT_EQ(o->ks, (std::vector<int>{5}));
  EXPECT_EQ(o->methods, (std::vector<std::string>{"icef", "icef-prior"}));
  // A test bench keeps the classic scene.
  a.validation = false;
  const Result<eval::BenchOptions> test = ResolveBenchOptions(a);
  ASSERT_TRUE(test.ok());
  EXPECT_FALSE(test->diverse);
}

TEST(BenchApp, StepsAloneDropTheTimeCap) {
  BenchAppOptions a;
  a.out = "b";
  a.steps = 50;
  EXPECT_EQ(ResolveBenchOptions(a)->time_budget_seconds, 0);
  a.time_budget = 30;
  EXPECT_EQ(ResolveBenchOptions(a)->time_budget_seconds, 30);
}

TEST(BenchApp, BadListsAndShardsNameTheOption) {
  BenchAppOptions a;
  a.out = "b";
  a.ks = "3,x";
  EXPECT_NE(ResolveBenchOptions(a).status().message().find("--k"), std::string::npos)
      << ResolveBenchOptions(a).status().message();
  a.ks.clear();
  a.shard = "3/2";
  EXPECT_FALSE(ResolveBenchOptions(a).ok());
  a.shard.clear();
  a.out.clear();
  EXPECT_NE(a.Validate().message().find("--out"), std::string::npos) << a.Validate().message();
}

TEST(BenchApp, RealBenchTakesTheGivenOptions) {
  BenchAppOptions a;
  a.out = "b";
  a.real = {"clip.mp4"};
  a.quick = true;
  a.ks = "3,5";
  a.resolution = 96;
  a.real_test_frames = 3;
  a.real_face_model = "ict";
  a.base.overrides = {"train.lambda_id=0.5"};
  a.base.threads = 2;
  const Result<RealBenchOptions> r = ResolveRealBenchOptions(a);
  ASSERT_TRUE(r.ok()) << r.status().message();
  RealBenchOptions quick;
  quick.ApplyQuick();
  EXPECT_EQ(r->sources, a.real);
  EXPECT_EQ(r->out_dir, "b");
  EXPECT_EQ(r->ks, (std::vector<int>{3, 5}));
  EXPECT_EQ(r->resolution, 96);                    // given
  EXPECT_EQ(r->steps, quick.steps);                // --quick's
  EXPECT_EQ(r->video_frames, quick.video_frames);  // not given
  EXPECT_EQ(r->test_frames, 3);
  EXPECT_EQ(r->face_model, "ict");
  EXPECT_EQ(r->threads, 2);
  ASSERT_FALSE(r->overrides.empty());
  EXPECT_EQ(r->overrides.back(), "train.lambda_id=0.5");
}

TEST(BenchApp, RealOnlyOptionsAndMergeWithoutOutAreRefused) {
  BenchAppOptions a;
  a.out = "b";
  a.video_frames = 10;  // without --real
  std::ostringstream log;
  EXPECT_NE(RunBench(a, log).message().find("--test and --video-frames go with --real"), std::string::npos);
  BenchAppOptions merge;
  merge.merge = {"shard0", "shard1"};
  EXPECT_NE(RunBench(merge, log).message().find("--out is required"), std::string::npos);
}

// A synthetic bench in ICT-FaceKit: every dataset re-expressed with its cameras held (53 ARKit-named
// weights, the procedural renders as the truth), the prior standing on ICT, the report saying so.
TEST(BenchApp, SyntheticBenchInIctReexpressesItsDatasets) {
  if (!std::filesystem::exists(face::IctModel::DefaultPath())) GTEST_SKIP() << "no face model";
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("icef_bench_ict_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  BenchAppOptions a;
  a.out = dir;
  a.quick = true;
  a.methods = {"icef-prior"};
  a.real_face_model = "ict";
  a.base.threads = 2;
  std::ostringstream log;
  ASSERT_TRUE(RunBench(a, log).ok()) << log.str();
  EXPECT_NE(log.str().find("re-expressing id1_k3 in ict"), std::string::npos) << log.str();
  const Result<Dataset> d = LoadDataset(dir / "data" / "id1_k3_ict");
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_EQ(d->expression_dim, 53);
  ASSERT_FALSE(d->test.empty());
  EXPECT_TRUE(d->test[0].tier.has_value());  // the truth's tiers kept
  EXPECT_TRUE(std::filesystem::exists(dir / "runs" / "id1_k3_icef-prior" / "metrics.json"));
  const Result<std::string> bench = ReadFile(dir / "bench.json");
  ASSERT_TRUE(bench.ok());
  EXPECT_NE(bench->find("\"face_model\": \"ict\""), std::string::npos) << *bench;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace icef
