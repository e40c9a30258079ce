// The trainer's NaN/Inf guard (issue 7): a non-finite loss term or gradient is detected in the
// step it appears, training stops with an error naming the step and the term, and the last
// checkpoint on disk stays byte-identical and loadable.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <string>

#include "icef/data/dataset.h"
#include "icef/io/atomic_file.h"
#include "icef/model/model_test_util.h"
#include "icef/synth/synthesize.h"
#include "icef/testing/tiny_dataset.h"
#include "icef/train/test_subject.h"
#include "icef/train/trainer.h"

namespace icef {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

RunConfig TinyRunConfig() {
  RunConfig c;
  c.model = testing_model::TinyModelConfig("icef");
  c.train.steps = 8;
  c.train.batch_rays = 64;
  c.train.checkpoint_every = 2;
  c.train.log_every = 1;
  c.train.smooth_max_samples = 64;
  c.train.occupancy_warmup = 100;
  c.train.threads = 1;
  return c;
}

// Index of the first parameter block whose name contains `part` (-1 when none).
int FindBlockContaining(const nn::ParameterStore& store, const std::string& part) {
  for (int i = 0; i < store.num_blocks(); ++i)
    if (store.block(i).name.find(part) != std::string::npos) return i;
  return -1;
}

struct GuardRun {
  Status status;                        // what Run returned
  std::optional<TrainSummary> summary;  // when it succeeded
  std::string ckpt_before;              // checkpoint bytes when the poison was injected
  std::string ckpt_after;               // checkpoint bytes after Run returned
  std::filesystem::path model_dir;
};

const Dataset& Subject() { return testing::TinySubject("nan_guard_subject"); }

// Trains the tiny config; after step `poison_step` completes, `poison` corrupts the model.
GuardRun RunWithPoison(const std::string& name, int64_t poison_step,
                       const std::function<void(AvatarModel&)>& poison,
                       const RunConfig& config = TinyRunConfig()) {
  const std::filesystem::path dir = testing::MakeTempDir(name);
  const Dataset& dataset = Subject();
  GuardRun run;
  run.model_dir = dir / "model";
  Result<std::unique_ptr<Trainer>> trainer = Trainer::Create(dataset, run.model_dir, config);
  EXPECT_TRUE(trainer.ok()) << trainer.status().message();
  if (!trainer.ok()) return run;
  const std::filesystem::path ckpt = run.model_dir / kCheckpointFile;
  Trainer& t = **trainer;
  Result<TrainSummary> summary = t.Run(
      [&](const TrainProgress& p) {
        if (p.step != poison_step) return;
        Result<std::string> bytes = ReadFile(ckpt);
        EXPECT_TRUE(bytes.ok()) << "no checkpoint before the poison: " << bytes.status().message();
        if (bytes.ok()) run.ckpt_before = *bytes;
        poison(t.model());
      },
      nullptr);
  run.status = summary.status();
  if (summary.ok()) run.summary = *summary;
  Result<std::string> after = ReadFile(ckpt);
  if (after.ok()) run.ckpt_after = *after;
  return run;
}

void ExpectCheckpointIntact(const GuardRun& run, int64_t expected_step) {
  ASSERT_FALSE(run.ckpt_before.empty());
  EXPECT_EQ(run.ckpt_before, run.ckpt_after) << "the last good checkpoint was overwritten";
  Result<LoadedModel> loaded = LoadModel(run.model_dir, Executor(1));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_EQ(loaded->state.step, expected_step);
  const nn::ParameterStore& store = loaded->model->store();
  for (int64_t i = 0; i < store.size(); ++i)
    ASSERT_TRUE(std::isfinite(store.params()[i])) << "parameter " << i;
}

TEST(NanGuard, NonFiniteLossNamesStepAndTermAndKeepsCheckpoint) {
  // NaN colour-MLP weights make every rendered colour NaN, hence the photometric loss; densities
  // and sample positions stay finite.
  const GuardRun run = RunWithPoison("nan_guard_loss", 3, [](AvatarModel& model) {
    const int block = FindBlockContaining(model.store(), "color");
    ASSERT_GE(block, 0) << "no colour MLP block in the model";
    for (float& w : model.store().params(block)) w = kNaN;
  });
  ASSERT_FALSE(run.status.ok()) << "training went on with NaN weights";
  const std::string& message = run.status.message();
  EXPECT_NE(message.find("step 3"), std::string::npos) << message;
  EXPECT_NE(message.find("'photo'"), std::string::npos) << message;
  EXPECT_NE(message.find("not finite"), std::string::npos) << message;
  ExpectCheckpointIntact(run, 2);
}

TEST(NanGuard, NonFiniteGradientNamesStepAndKeepsCheckpoint) {
  // An Inf already in the gradient buffer survives the step's accumulation; the loss stays finite.
  const GuardRun run = RunWithPoison("nan_guard_grad", 5, [](AvatarModel& model) {
    const int block = FindBlockContaining(model.store(), "color");
    ASSERT_GE(block, 0);
    model.store().grads(block)[0] = std::numeric_limits<float>::infinity();
  });
  ASSERT_FALSE(run.status.ok()) << "training went on with an infinite gradient";
  const std::string& message = run.status.message();
  EXPECT_NE(message.find("step 5"), std::string::npos) << message;
  EXPECT_NE(message.find("gradient"), std::string::npos) << message;
  ExpectCheckpointIntact(run, 4);
}

TEST(NanGuard, CleanRunIsNotStopped) {
  // The same run without poison trains to the end: the guard does not fire on finite values.
  const GuardRun run = RunWithPoison("nan_guard_clean", 3, [](AvatarModel&) {});
  EXPECT_TRUE(run.status.ok()) << run.status.message();
}

TEST(NanGuard, OnNonfiniteDefaultsToStop) {
  EXPECT_EQ(TrainConfig().on_nonfinite, "stop");
  RunConfig c = TinyRunConfig();
  EXPECT_FALSE(c.ApplyOverride("train.on_nonfinite=ignore").ok());
  EXPECT_TRUE(c.ApplyOverride("train.on_nonfinite=skip").ok());
}

RunConfig SkipConfig(int64_t steps) {
  RunConfig c = TinyRunConfig();
  c.train.on_nonfinite = "skip";
  c.train.steps = steps;
  return c;
}

TEST(NanGuard, SkipModeSkipsANonFiniteStepAndReportsIt) {
  // One infinite gradient (as in NonFiniteGradientNamesStepAndKeepsCheckpoint): with "skip" the
  // step after the poison is skipped, training goes on to the end, and the count is reported.
  const GuardRun run = RunWithPoison(
      "nan_guard_skip_once", 5,
      [](AvatarModel& model) {
        const int block = FindBlockContaining(model.store(), "color");
        ASSERT_GE(block, 0);
        model.store().grads(block)[0] = std::numeric_limits<float>::infinity();
      },
      SkipConfig(8));
  ASSERT_TRUE(run.status.ok()) << run.status.message();
  ASSERT_TRUE(run.summary.has_value());
  EXPECT_EQ(run.summary->steps, 8);
  EXPECT_EQ(run.summary->skipped_steps, 1);
  EXPECT_NE(run.summary->BriefReport().find("steps skipped for a non-finite loss or gradient: 1"),
            std::string::npos)
      << run.summary->BriefReport();
  const Json summary = Json::parse(ReadFile(run.model_dir / "summary.json").value());
  EXPECT_EQ(summary["skipped_steps"].get<int64_t>(), 1);
  // The log marks the skipped step (the 6th); the checkpoint holds the count and finite parameters.
  const std::string log = ReadFile(run.model_dir / "train_log.jsonl").value();
  EXPECT_NE(log.find("\"step\":6,"), std::string::npos) << log;
  EXPECT_NE(log.find("\"skipped\":true"), std::string::npos) << log;
  EXPECT_EQ(log.find("\"skipped\":true"), log.rfind("\"skipped\":true"))
      << "more than one skipped step: " << log;
  Result<LoadedModel> loaded = LoadModel(run.model_dir, Executor(1));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_EQ(loaded->state.step, 8);
  EXPECT_EQ(loaded->state.skipped_steps, 1);
  for (int64_t i = 0; i < loaded->model->store().size(); ++i)
    ASSERT_TRUE(std::isfinite(loaded->model->store().params()[i])) << "parameter " << i;
}

TEST(NanGuard, SkipModeStopsAfterTooManyNonFiniteStepsInARow) {
  // NaN colour weights never go away: steps 3..12 are skipped, step 13 is the 11th non-finite step
  // in a row and stops training; no checkpoint was written after a skipped step, so the one of
  // step 2 (the last before the poison) is intact.
  const GuardRun run = RunWithPoison(
      "nan_guard_skip_many", 3,
      [](AvatarModel& model) {
        const int block = FindBlockContaining(model.store(), "color");
        ASSERT_GE(block, 0);
        for (float& w : model.store().params(block)) w = kNaN;
      },
      SkipConfig(30));
  ASSERT_FALSE(run.status.ok()) << "training went on with NaN weights";
  const std::string& message = run.status.message();
  EXPECT_NE(message.find("step 13: loss term 'photo' is not finite"), std::string::npos) << message;
  EXPECT_NE(message.find("11th non-finite step in a row"), std::string::npos) << message;
  EXPECT_NE(message.find("at most 10"), std::string::npos) << message;
  ExpectCheckpointIntact(run, 2);
}

}  // namespace
}  // namespace icef
