#include "icef/train/run_setup.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "icef/model/model_test_util.h"
#include "icef/synth/synthesize.h"
#include "icef/testing/tiny_dataset.h"
#include "icef/train/test_subject.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

const Dataset& Subject() { return testing::TinySubject("run_setup_subject"); }

RunConfig TinyConfig(const std::string& method) {
  RunConfig c;
  c.model = testing_model::TinyModelConfig(method);
  c.train.seed = 5;
  return c;
}

// A trial function for runs that must not train trials.
const StartTrialFn kNoTrials = [](std::unique_ptr<AvatarModel>, const TrainingData&,
                                  int) -> Result<std::vector<double>> {
  ADD_FAILURE() << "no start trial expected";
  return Status::Error("no start trial expected");
};

std::string ParamBytes(const AvatarModel& model) {
  const nn::ParameterStore& s = model.store();
  return std::string(reinterpret_cast<const char*>(s.params()), s.size() * sizeof(float));
}

TEST(RunSetupOptionsTest, FollowTheRunConfig) {
  RunConfig config = TinyConfig("icef");
  config.train.start_trials = 3;
  config.train.start_trial_steps = 8;
  config.train.density_start_steps = 2;
  config.model.visual_hull.margin_px = 4;
  RunSetupOptions o = RunSetupOptions::FromConfig(config);
  EXPECT_FALSE(o.fit_face);
  EXPECT_EQ(o.seed, 5u);
  EXPECT_EQ(o.start_trials, 3);
  EXPECT_EQ(o.start_trial_steps, 8);
  EXPECT_EQ(o.density_start.steps, 2);
  EXPECT_EQ(o.hull_margin_px, 4);
  EXPECT_EQ(o.hull_resolution, config.model.occupancy.resolution);
  EXPECT_TRUE(o.Validate().ok());
  EXPECT_NE(o.ToString().find("start_trials=3"), std::string::npos) << o.ToString();
  // The face model is fitted for the methods on the face-model prior alone.
  for (const char* method : {"icef-prior", "warp-prior"})
    EXPECT_TRUE(RunSetupOptions::FromConfig(TinyConfig(method)).fit_face) << method;
  for (const char* method : {"icef", "warp", "nerface"})
    EXPECT_FALSE(RunSetupOptions::FromConfig(TinyConfig(method)).fit_face) << method;
  o.start_trial_steps = 3;
  EXPECT_FALSE(o.Validate().ok());
  o = RunSetupOptions{};
  o.hull_resolution = 0;
  EXPECT_FALSE(o.Validate().ok());
}

TEST(RunSetupTest, TheHullComesFromMasksAlone) {
  const Dataset& subject = Subject();
  Result<TrainingData> with_alpha = TrainingData::Load(subject);
  ASSERT_TRUE(with_alpha.ok()) << with_alpha.status().message();
  ASSERT_TRUE(with_alpha->has_alpha());
  RunSetupOptions o;
  o.hull_resolution = 16;
  const Aabb aabb = subject.aabb;
  const std::vector<uint8_t> hull = VisualHull(*with_alpha, aabb, o, Executor(2));
  ASSERT_EQ(hull.size(), size_t(16 * 16 * 16));
  int64_t kept = 0;
  for (uint8_t c : hull) kept += c;
  EXPECT_GT(kept, 0);
  EXPECT_LT(kept, int64_t(hull.size()));  // something is carved
  EXPECT_EQ(VisualHull(*with_alpha, aabb, o, Executor(1)), hull);
  o.visual_hull = false;
  EXPECT_TRUE(VisualHull(*with_alpha, aabb, o, Executor(2)).empty());
  // Images without alpha have no masks, so no hull.
  const Dataset rgb = testing::WriteTinyDataset(testing::MakeTempDir("run_setup_rgb"));
  Result<TrainingData> without_alpha = TrainingData::Load(rgb);
  ASSERT_TRUE(without_alpha.ok()) << without_alpha.status().message();
  ASSERT_FALSE(without_alpha->has_alpha());
  o.visual_hull = true;
  EXPECT_TRUE(VisualHull(*without_alpha, rgb.aabb, o, Executor(2)).empty());
}

TEST(RunSetupTest, TheFaceModelIsFittedForTheFacePriorAlone) {
  for (const char* method : {"icef", "icef-prior"}) {
    const RunConfig config = TinyConfig(method);
    Result<RunSetup> run =
        PrepareRun(Subject(), config.model, RunSetupOptions::FromConfig(config), kNoTrials, Executor(2));
    ASSERT_TRUE(run.ok()) << method << ": " << run.status().message();
    const bool prior = std::string(method) == "icef-prior";
    EXPECT_EQ(run->model->setup().face_fit.has_value(), prior) << method;
    EXPECT_FALSE(run->hull_cells.empty()) << method;  // RGBA images: the hull is carved
    EXPECT_EQ(run->start_trial, 0);
    EXPECT_TRUE(run->start_trials_note.empty());
    EXPECT_TRUE(run->density_start_note.empty());  // density_start.steps = 0
    EXPECT_EQ(run->data.num_frames(), 3);
  }
}

// Each trial's losses are given: trial t's late quarter (steps 6 and 7 of 8) averages late[t].
TEST(RunSetupTest, StartTrialsKeepTheLowestLateLossDeterministically) {
  const std::vector<double> late = {0.5, 0.25, 0.25, 0.75};
  std::vector<uint64_t> seeds;
  const ModelFactory make_model = [&](uint64_t seed) -> Result<std::unique_ptr<AvatarModel>> {
    seeds.push_back(seed);
    return std::unique_ptr<AvatarModel>();
  };
  int calls = 0;
  const StartTrialFn run_trial = [&](std::unique_ptr<AvatarModel>, const TrainingData&,
                                     int steps) -> Result<std::vector<double>> {
    std::vector<double> losses(steps, 9.0);  // early steps do not count
    losses[steps - 1] = losses[steps - 2] = late[calls++];
    return losses;
  };
  RunSetupOptions o;
  o.seed = 11;
  o.start_trials = 4;
  o.start_trial_steps = 8;
  const TrainingData data;
  Result<StartTrialChoice> a = ChooseStartTrial(make_model, data, o, run_trial);
  ASSERT_TRUE(a.ok()) << a.status().message();
  EXPECT_EQ(a->trial, 1);  // the first of the two lowest
  EXPECT_EQ(
      a->note,
      "start trials: batch loss over steps 6-8 of trial 0 0.5, trial 1 0.25, trial 2 0.25, trial 3 0.75; "
      "training starts from trial 1's initialisation");
  ASSERT_EQ(seeds.size(), 4u);
  EXPECT_EQ(seeds[0], 11u);  // trial 0 is the run's own initialisation
  for (int t = 0; t < 4; ++t) EXPECT_EQ(seeds[t], StartTrialSeed(11, t));
  EXPECT_NE(StartTrialSeed(11, 1), StartTrialSeed(11, 2));
  calls = 0;
  Result<StartTrialChoice> b = ChooseStartTrial(make_model, data, o, run_trial);
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(b->trial, a->trial);
  EXPECT_EQ(b->note, a->note);
  o.start_trials = 1;  // one trial: nothing to try
  Result<StartTrialChoice> single = ChooseStartTrial(make_model, data, o, kNoTrials);
  ASSERT_TRUE(single.ok());
  EXPECT_EQ(single->trial, 0);
  EXPECT_TRUE(single->note.empty());
}

// PrepareRun trains the model of the kept trial's initialisation, carved to the hull.
TEST(RunSetupTest, TheModelStartsFromTheKeptTrial) {
  RunConfig config = TinyConfig("icef");
  RunSetupOptions o = RunSetupOptions::FromConfig(config);
  o.start_trials = 3;
  o.start_trial_steps = 4;
  int trial = 0;
  const StartTrialFn run_trial = [&](std::unique_ptr<AvatarModel> model, const TrainingData& data,
                                     int steps) -> Result<std::vector<double>> {
    EXPECT_NE(model, nullptr);
    EXPECT_EQ(data.num_frames(), 3);
    return std::vector<double>(steps, trial++ == 2 ? 1.0 : 2.0);
  };
  Result<RunSetup> run = PrepareRun(Subject(), config.model, o, run_trial, Executor(2));
  ASSERT_TRUE(run.ok()) << run.status().message();
  EXPECT_EQ(run->start_trial, 2);
  EXPECT_NE(run->start_trials_note.find("training starts from trial 2's initialisation"), std::string::npos);
  RunSetupOptions plain = RunSetupOptions::FromConfig(config);
  plain.seed = StartTrialSeed(o.seed, 2);
  Result<RunSetup> direct = PrepareRun(Subject(), config.model, plain, kNoTrials, Executor(1));
  ASSERT_TRUE(direct.ok()) << direct.status().message();
  EXPECT_TRUE(ParamBytes(*run->model) == ParamBytes(*direct->model));
  EXPECT_EQ(run->hull_cells, direct->hull_cells);
}

TEST(RunSetupTest, AnErrorNamesItsStep) {
  const RunConfig config = TinyConfig("icef");
  RunSetupOptions o = RunSetupOptions::FromConfig(config);
  o.start_trials = 2;
  o.start_trial_steps = 4;
  const StartTrialFn failing = [](std::unique_ptr<AvatarModel>, const TrainingData&,
                                  int) -> Result<std::vector<double>> {
    return Status::Error("step 3: loss term 'rgb' is not finite");
  };
  Result<RunSetup> run = PrepareRun(Subject(), config.model, o, failing, Executor(2));
  ASSERT_FALSE(run.ok());
  EXPECT_EQ(run.status().message(), "start trial 0: step 3: loss term 'rgb' is not finite");
  // The face model needs its own expression space: the tiny dataset's "e0".."e3" are not it.
  const Dataset other = testing::WriteTinyDataset(testing::MakeTempDir("run_setup_other_expressions"));
  const RunConfig prior = TinyConfig("icef-prior");
  run = PrepareRun(other, prior.model, RunSetupOptions::FromConfig(prior), kNoTrials, Executor(2));
  ASSERT_FALSE(run.ok());
  EXPECT_EQ(run.status().message().rfind("face model fit: ", 0), 0u) << run.status().message();
  // Invalid options are refused before anything runs.
  o.start_trials = 0;
  run = PrepareRun(Subject(), config.model, o, kNoTrials, Executor(2));
  ASSERT_FALSE(run.ok());
  EXPECT_NE(run.status().message().find("start_trials"), std::string::npos) << run.status().message();
  // Without a face fit the density start has nothing to do.
  Result<RunSetup> plain =
      PrepareRun(Subject(), config.model, RunSetupOptions::FromConfig(config), kNoTrials, Executor(2));
  ASSERT_TRUE(plain.ok()) << plain.status().message();
  RunSetupOptions seeded = RunSetupOptions::FromConfig(config);
  seeded.density_start.steps = 3;
  Result<std::string> note = SeedDensity(seeded, plain->model.get(), Executor(2));
  ASSERT_TRUE(note.ok());
  EXPECT_TRUE(note->empty());
}

}  // namespace
}  // namespace icef
