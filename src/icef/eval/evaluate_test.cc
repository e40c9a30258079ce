#include "icef/eval/evaluate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>

#include "icef/eval/expression_fidelity.h"
#include "icef/eval/metrics.h"
#include "icef/io/atomic_file.h"
#include "icef/model/render_image.h"
#include "icef/study/report.h"
#include "icef/synth/synthesize.h"
#include "icef/train/trainer.h"

namespace icef::eval {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("icef_evaluate_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// A hand-made metrics file: two observed frames, three far frames (one without identity), no
// near/moderate frames, LPIPS null everywhere.
constexpr const char* kHandMade = R"({
  "method": "icef",
  "frames": [
    {"file_path": "a.png", "tier": "observed", "delta": 0, "psnr": 20.0, "ssim": 0.5, "lpips": null,
     "id_cosine": 0.98, "id_distance": 0.2, "id_distance_gt": 0.3},
    {"file_path": "b.png", "tier": "observed", "delta": 0, "psnr": 22.0, "ssim": 0.7, "lpips": null,
     "id_cosine": 0.96, "id_distance": 0.4, "id_distance_gt": 0.5},
    {"file_path": "c.png", "tier": "far", "delta": 1.0, "psnr": 15.0, "ssim": 0.25, "lpips": null,
     "id_cosine": 0.9, "id_distance": 0.5, "id_distance_gt": 0.7},
    {"file_path": "d.png", "tier": "far", "delta": 1.5, "psnr": 18.0, "ssim": 0.5, "lpips": null,
     "id_cosine": 0.8, "id_distance": 0.75, "id_distance_gt": 0.9},
    {"file_path": "e.png", "tier": "far", "delta": 2.0, "psnr": 12.0, "ssim": 0.75, "lpips": null,
     "id_cosine": null, "id_distance": null, "id_distance_gt": null}
  ],
  "tiers": {
    "observed": {"count": 0, "psnr": null, "ssim": null, "lpips": null, "id_cosine": null,
                 "id_distance": null, "id_distance_gt": null, "id_share_under_0_6": null},
    "near": {"count": 0, "psnr": null, "ssim": null, "lpips": null, "id_cosine": null,
             "id_distance": null, "id_distance_gt": null, "id_share_under_0_6": null},
    "moderate": {"count": 0, "psnr": null, "ssim": null, "lpips": null, "id_cosine": null,
                 "id_distance": null, "id_distance_gt": null, "id_share_under_0_6": null},
    "far": {"count": 0, "psnr": null, "ssim": null, "lpips": null, "id_cosine": null,
            "id_distance": null, "id_distance_gt": null, "id_share_under_0_6": null}
  }
})";

TEST(EvaluateTest, AggregatesHandMadeMetricsFilePerTier) {
  const fs::path dir = TempDir("handmade");
  ASSERT_TRUE(WriteFileAtomic(dir / "metrics.json", kHandMade).ok());
  const Result<EvalResult> read = ReadMetricsFile(dir / "metrics.json");
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_EQ(read->frames.size(), 5u);
  const auto tiers = AggregateTiers(read->frames);

  const TierMetrics& obs = tiers[TierIndex(Tier::kObserved)];
  EXPECT_EQ(obs.count, 2);
  EXPECT_DOUBLE_EQ(*obs.psnr, 21.0);
  EXPECT_DOUBLE_EQ(*obs.ssim, 0.6);
  EXPECT_FALSE(obs.lpips.has_value());
  EXPECT_FALSE(obs.id_distance_reference.has_value());  // absent from the file: null
  EXPECT_DOUBLE_EQ(*obs.id_cosine, 0.97);
  EXPECT_DOUBLE_EQ(*obs.id_distance, 0.3);
  EXPECT_DOUBLE_EQ(*obs.id_distance_gt, 0.4);
  EXPECT_DOUBLE_EQ(*obs.id_share_under_0_6, 1.0);
  EXPECT_EQ(obs.id_count, 2);
  EXPECT_DOUBLE_EQ(obs.mean_delta, 0.0);

  const TierMetrics& far = tiers[TierIndex(Tier::kFar)];
  EXPECT_EQ(far.count, 3);
  EXPECT_DOUBLE_EQ(*far.psnr, 15.0);
  EXPECT_DOUBLE_EQ(*far.ssim, 0.5);
  // Identity means over the two frames that have it.
  EXPECT_DOUBLE_EQ(*far.id_cosine, 0.85);
  EXPECT_DOUBLE_EQ(*far.id_distance, 0.625);
  EXPECT_DOUBLE_EQ(*far.id_distance_gt, 0.8);
  EXPECT_DOUBLE_EQ(*far.id_share_under_0_6, 0.5);
  EXPECT_EQ(far.id_count, 2);
  EXPECT_DOUBLE_EQ(far.mean_delta, 1.5);

  for (Tier t : {Tier::kNear, Tier::kModerate}) {
    const TierMetrics& m = tiers[TierIndex(t)];
    EXPECT_EQ(m.count, 0);
    EXPECT_FALSE(m.psnr.has_value());
    EXPECT_FALSE(m.id_share_under_0_6.has_value());
  }

  // Written back: nulls stay null, the tiers are the aggregates, and it reads back equal.
  EvalResult result = *read;
  result.tiers = tiers;
  ASSERT_TRUE(WriteMetricsFile(dir / "out.json", result).ok());
  const Result<Json> json = ReadJsonFile(dir / "out.json");
  ASSERT_TRUE(json.ok());
  EXPECT_TRUE((*json)["frames"][0]["lpips"].is_null());
  EXPECT_TRUE((*json)["frames"][4]["id_distance"].is_null());
  EXPECT_TRUE((*json)["tiers"]["near"]["psnr"].is_null());
  EXPECT_DOUBLE_EQ((*json)["tiers"]["far"]["id_distance"].get<double>(), 0.625);
  for (const char* key :
       {"count", "psnr", "ssim", "lpips", "id_cosine", "id_distance", "id_distance_gt", "id_share_under_0_6"})
    EXPECT_TRUE((*json)["tiers"]["observed"].contains(key)) << key;
  const Result<EvalResult> again = ReadMetricsFile(dir / "out.json");
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_DOUBLE_EQ(*again->tiers[TierIndex(Tier::kFar)].id_cosine, 0.85);
  EXPECT_EQ(again->tiers[TierIndex(Tier::kFar)].count, 3);
  const std::string table = again->Table();
  EXPECT_NE(table.find("observed"), std::string::npos);
  EXPECT_NE(table.find("21.00"), std::string::npos);
  EXPECT_NE(table.find("50%"), std::string::npos);
  fs::remove_all(dir);
}

TEST(EvaluateTest, MetricsFileErrorsNameTheField) {
  const fs::path dir = TempDir("errors");
  std::string text = kHandMade;
  text.replace(text.find("\"tier\": \"far\""), 13, "\"tier\": \"farther\"");
  ASSERT_TRUE(WriteFileAtomic(dir / "bad.json", text).ok());
  Result<EvalResult> r = ReadMetricsFile(dir / "bad.json");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("frames[2].tier"), std::string::npos) << r.status().message();

  text = kHandMade;
  text.replace(text.find("\"psnr\": 22.0"), 12, "\"psnr\": \"x\"");
  ASSERT_TRUE(WriteFileAtomic(dir / "bad2.json", text).ok());
  r = ReadMetricsFile(dir / "bad2.json");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("frames[1].psnr"), std::string::npos) << r.status().message();
  fs::remove_all(dir);
}

TEST(EvaluateTest, TrainingFitRoundTripsAndOldFilesHaveNone) {
  // A metrics file from before the training-view fit: it parses, with an empty fit.
  const Result<EvalResult> old = EvalResult::FromJson(Json::parse(kHandMade), "old.json");
  ASSERT_TRUE(old.ok()) << old.status().message();
  EXPECT_EQ(old->train_fit.count, 0);
  EXPECT_TRUE(old->train_fit.frames.empty());
  EXPECT_FALSE(old->train_fit.face_psnr.has_value());
  EXPECT_NE(old->Table().find("training-view fit: unavailable"), std::string::npos) << old->Table();
  Json null_fit = Json::parse(kHandMade);
  null_fit["train_fit"] = nullptr;
  EXPECT_TRUE(EvalResult::FromJson(null_fit, "null.json").ok());

  // Means over the frames with a value; the frame without landmarks has no face PSNR.
  EvalResult result = *old;
  result.train_fit = TrainingFit::Of(
      {TrainFrameFit{"images/train_000.png", 32.0, 400, 0.8, 24.0, "renders/fit_train_000.png"},
       TrainFrameFit{"images/train_001.png", 28.0, 380, 0.6, 26.0, ""},
       TrainFrameFit{"images/train_002.png", std::nullopt, 0, std::nullopt, 25.0, ""}});
  const TrainingFit& fit = result.train_fit;
  EXPECT_EQ(fit.count, 3);
  EXPECT_EQ(fit.face_count, 2);
  EXPECT_DOUBLE_EQ(*fit.face_psnr, 30.0);
  EXPECT_DOUBLE_EQ(*fit.face_psnr_min, 28.0);
  EXPECT_DOUBLE_EQ(*fit.psnr, 25.0);
  EXPECT_DOUBLE_EQ(*fit.face_detail, 0.7);
  EXPECT_NE(
      result.Table().find("training-view fit: face-region PSNR 30.00 dB (worst 28.00, 2 of 3 views), full "
                          "image 25.00 dB, face detail 0.70 x the truth's"),
      std::string::npos)
      << result.Table();

  const Json json = result.ToJson();
  const Json& j = json["train_fit"];
  EXPECT_EQ(j["count"], 3);
  EXPECT_EQ(j["face_count"], 2);
  EXPECT_DOUBLE_EQ(j["face_psnr"].get<double>(), 30.0);
  EXPECT_DOUBLE_EQ(j["face_psnr_min"].get<double>(), 28.0);
  ASSERT_EQ(j["frames"].size(), 3u);
  EXPECT_EQ(j["frames"][0]["file_path"], "images/train_000.png");
  EXPECT_EQ(j["frames"][0]["render"], "renders/fit_train_000.png");
  EXPECT_EQ(j["frames"][0]["face_pixels"], 400);
  EXPECT_TRUE(j["frames"][2]["face_psnr"].is_null());
  const Result<EvalResult> again = EvalResult::FromJson(json, "new.json");
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_EQ(again->ToJson(), json);
  EXPECT_EQ(again->train_fit.frames[1].file_path, "images/train_001.png");

  // Errors name the field.
  Json bad = json;
  bad["train_fit"]["frames"][1]["psnr"] = "x";
  Result<EvalResult> r = EvalResult::FromJson(bad, "bad.json");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("bad.json: train_fit.frames[1].psnr"), std::string::npos)
      << r.status().message();
  bad = json;
  bad["train_fit"].erase("count");
  r = EvalResult::FromJson(bad, "bad.json");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("train_fit.count"), std::string::npos) << r.status().message();
}

// A tiny synthetic dataset (3 training frames, 32 px) in dir/data.
Dataset TinySyntheticDataset(const fs::path& dir, const Executor& executor) {
  synth::SynthOptions so;
  so.out_dir = dir / "data";
  so.num_train = 3;
  so.resolution = 32;
  so.test_views = 1;
  so.novel_per_tier = 1;
  so.render.supersample = 1;
  Dataset written;
  const Status synthesized = synth::SynthesizeDataset(so, executor, nullptr, &written);
  ICEF_CHECK(synthesized.ok(), synthesized.message());
  return LoadDataset(so.out_dir).value();
}

// A tiny icef model trained for `steps` steps on `dataset` (0: as initialised).
std::unique_ptr<Trainer> TinyTrainer(const Dataset& dataset, const fs::path& dir, int steps) {
  RunConfig config;
  config.model.method = "icef";
  config.model.static_field.grid.num_levels = 4;
  config.model.static_field.grid.log2_table_size = 10;
  config.model.static_field.grid.finest_resolution = 32;
  config.model.static_field.density_hidden = 16;
  config.model.static_field.color_hidden = {16};
  config.model.deformation.hidden = {16, 16};
  config.model.sampler.num_samples = 16;
  config.model.occupancy.resolution = 16;
  config.train.steps = std::max(steps, 1);  // 0: created, not trained
  config.train.batch_rays = 256;
  config.train.checkpoint_every = 0;
  config.train.threads = 2;
  std::unique_ptr<Trainer> trainer = Trainer::Create(dataset, dir / "model", config).value();
  if (steps > 0) {
    const Result<TrainSummary> trained = trainer->Run(nullptr, nullptr);
    ICEF_CHECK(trained.ok(), trained.status().message());
  }
  return trainer;
}

// A tiny model trained for a few steps on a tiny synthetic dataset, evaluated end to end.
TEST(EvaluateTest, EvaluatesTinyTrainedModel) {
  const fs::path dir = TempDir("model");
  const Executor executor(2);
  const Dataset dataset = TinySyntheticDataset(dir, executor);
  const std::unique_ptr<Trainer> trainer = TinyTrainer(dataset, dir, 5);
  const AvatarModel& model = trainer->model();

  EvalOptions options;
  options.out_dir = dir / "eval";
  EvalNetworks networks;  // no identity network, no LPIPS: those metrics must be null
  networks.identity_note = "test";
  const Result<EvalResult> result = EvaluateModel(model, dataset, options, networks, executor, nullptr);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_EQ(result->method, "icef");
  ASSERT_EQ(result->frames.size(), dataset.test.size());
  int total = 0;
  for (Tier t : AllTiers()) total += result->tiers[TierIndex(t)].count;
  EXPECT_EQ(total, static_cast<int>(dataset.test.size()));
  EXPECT_EQ(result->tiers[TierIndex(Tier::kObserved)].count, 3);
  EXPECT_EQ(result->tiers[TierIndex(Tier::kFar)].count, 1);
  EXPECT_FALSE(result->identity_available);
  for (size_t i = 0; i < result->frames.size(); ++i) {
    const FrameMetrics& f = result->frames[i];
    const Frame& frame = dataset.test[i];
    EXPECT_EQ(f.file_path, frame.file_path);
    EXPECT_EQ(f.tier, *frame.tier);
    EXPECT_DOUBLE_EQ(f.delta, *frame.delta);
    EXPECT_FALSE(f.lpips.has_value());
    EXPECT_FALSE(f.id_distance.has_value());
    ASSERT_TRUE(f.psnr.has_value());
    ASSERT_TRUE(f.ssim.has_value());
    EXPECT_TRUE(fs::exists(options.out_dir / f.render_path)) << f.render_path;
    // The same numbers from an independent render at the frame's camera and expression.
    const RenderedImage r = RenderImage(model, frame.camera, frame.expression, dataset.background, executor);
    const Image gt = CompositeOver(*LoadFrameImage(dataset, frame), dataset.background);
    EXPECT_DOUBLE_EQ(*f.psnr, *Psnr(r.color, gt));
    EXPECT_DOUBLE_EQ(*f.ssim, *Ssim(r.color, gt));
    // Fine detail inside the face region (the hull of the frame's landmarks).
    const Image face = FaceRegion(gt.width, gt.height, *frame.landmarks_2d);
    ASSERT_TRUE(f.face_detail.has_value()) << f.file_path;
    EXPECT_DOUBLE_EQ(*f.face_detail, *DetailRatio(r.color, gt, &face));
    EXPECT_NEAR(f.model_delta, *frame.delta, 1e-5);
    EXPECT_EQ(f.nearest_index, r.nearest.index);
  }
  EXPECT_TRUE(fs::exists(options.out_dir / "renders" / "neutral_000.png"));
  // Expression fidelity: every synthetic test frame has landmarks and a neutral, so region PSNR and
  // the neutral floor are measured everywhere, and gain/corr wherever the true change is not negligible.
  for (const FrameMetrics& f : result->frames) {
    ASSERT_TRUE(f.region_psnr && f.psnr_neutral_floor && f.expr_true_rms) << f.file_path;
    EXPECT_EQ(f.expr_gain.has_value(), *f.expr_true_rms >= kNegligibleExpressionRms);
  }
  const TierMetrics& far = result->tiers[TierIndex(Tier::kFar)];
  EXPECT_EQ(far.expr_count + far.expr_negligible, far.count);
  double far_detail = 0;
  for (const FrameMetrics& f : result->frames) far_detail += f.tier == Tier::kFar ? *f.face_detail : 0.0;
  ASSERT_TRUE(far.face_detail.has_value());
  EXPECT_DOUBLE_EQ(*far.face_detail, far_detail / far.count);
  // The training-view fit: every training frame rendered back, with finite values equal to an
  // independent render's; the face region is the hull of the frame's landmarks.
  const TrainingFit& fit = result->train_fit;
  ASSERT_EQ(fit.count, static_cast<int>(dataset.train.size()));
  ASSERT_EQ(fit.frames.size(), dataset.train.size());
  EXPECT_EQ(fit.face_count, fit.count);
  ASSERT_TRUE(fit.face_psnr && fit.face_psnr_min && fit.psnr);
  EXPECT_LE(*fit.face_psnr_min, *fit.face_psnr);
  for (size_t i = 0; i < fit.frames.size(); ++i) {
    const TrainFrameFit& f = fit.frames[i];
    const Frame& frame = dataset.train[i];
    EXPECT_EQ(f.file_path, frame.file_path);
    ASSERT_TRUE(f.psnr && f.face_psnr) << f.file_path;
    EXPECT_TRUE(std::isfinite(*f.psnr) && std::isfinite(*f.face_psnr));
    const RenderedImage r = RenderImage(model, frame.camera, frame.expression, dataset.background, executor);
    const Image gt = CompositeOver(*LoadFrameImage(dataset, frame), dataset.background);
    const Image face = FaceRegion(gt.width, gt.height, *frame.landmarks_2d);
    int pixels = 0;
    for (float v : face.pixels) pixels += v > 0.5f;
    EXPECT_EQ(f.face_pixels, pixels);
    EXPECT_GT(f.face_pixels, 0);
    EXPECT_LT(f.face_pixels, gt.width * gt.height);
    EXPECT_DOUBLE_EQ(*f.psnr, *Psnr(r.color, gt));
    EXPECT_DOUBLE_EQ(*f.face_psnr, *Psnr(r.color, gt, &face));
    ASSERT_TRUE(f.face_detail.has_value());
    EXPECT_DOUBLE_EQ(*f.face_detail, *DetailRatio(r.color, gt, &face));
    EXPECT_EQ(f.render_path, "renders/fit_" + fs::path(frame.file_path).stem().string() + ".png");
    EXPECT_TRUE(fs::exists(options.out_dir / f.render_path)) << f.render_path;
    const Result<Image> pair = ReadImage(
        options.out_dir / ("renders/fit_" + fs::path(frame.file_path).stem().string() + "_vs_truth.png"));
    ASSERT_TRUE(pair.ok()) << pair.status().message();
    EXPECT_EQ(pair->width, 2 * gt.width);  // truth | render
  }
  EXPECT_TRUE(fs::exists(options.out_dir / "renders" / "fit_train_000.png"));

  // A model that renders no expression (every frame at 0 x beta): its change against its own neutral
  // is exactly zero, so it reproduces none of the expression, and scores the render's neutral PSNR.
  EvalOptions still;
  still.expression_scale = 0;
  const Result<EvalResult> zero = EvaluateModel(model, dataset, still, networks, executor, nullptr);
  ASSERT_TRUE(zero.ok()) << zero.status().message();
  EXPECT_EQ(zero->expression_scale, 0.0);
  int gains = 0;
  for (const FrameMetrics& f : zero->frames) {
    if (!f.expr_gain) continue;
    ++gains;
    EXPECT_EQ(*f.expr_gain, 0.0) << f.file_path;
    EXPECT_FALSE(f.expr_corr.has_value());
  }
  EXPECT_GT(gains, 0);
  EXPECT_EQ(*zero->tiers[TierIndex(Tier::kFar)].expr_gain, 0.0);
  const Result<EvalResult> reread = EvalResult::FromJson(zero->ToJson(), "zero");
  ASSERT_TRUE(reread.ok()) << reread.status().message();
  EXPECT_EQ(reread->ToJson(), zero->ToJson());
  EXPECT_NE(zero->Table().find("every frame rendered at 0 x its expression"), std::string::npos);
  // ... and in the bench verdict it never beats the real model (here labelled as a baseline).
  RunRecord real_run, still_run;
  real_run.id = RunId{1, 3, "icef"};
  real_run.metrics = *result;
  still_run.id = RunId{1, 3, "warp"};
  still_run.metrics = *zero;
  still_run.metrics.method = "warp";
  const Aggregate aggregate = AggregateRuns({real_run, still_run});
  for (Tier tier : {Tier::kNear, Tier::kModerate, Tier::kFar})
    EXPECT_EQ(ComparePair(aggregate, 3, tier, "warp", "icef").outcome, Outcome::kUnderExpresses)
        << TierName(tier);

  // Frames without a stored tier get it from their delta and the dataset's thresholds.
  Dataset untiered = dataset;
  for (Frame& f : untiered.test) f.tier.reset();
  EvalOptions no_renders;
  const Result<EvalResult> derived = EvaluateModel(model, untiered, no_renders, networks, executor, nullptr);
  ASSERT_TRUE(derived.ok()) << derived.status().message();
  for (size_t i = 0; i < derived->frames.size(); ++i)
    EXPECT_EQ(derived->frames[i].tier, dataset.test[i].tier) << i;

  // With the face-identity network (when installed): identity metrics on every frame where a
  // face chip could be made (the dataset has landmarks, so all of them).
  Result<FaceIdentity> identity = FaceIdentity::Load({});
  if (identity.ok()) {
    networks.identity = &*identity;
    options.out_dir.clear();
    const Result<EvalResult> with_id = EvaluateModel(model, dataset, options, networks, executor, nullptr);
    ASSERT_TRUE(with_id.ok()) << with_id.status().message();
    EXPECT_TRUE(with_id->identity_available);
    for (const FrameMetrics& f : with_id->frames) {
      EXPECT_EQ(f.landmarks, "dataset");
      ASSERT_TRUE(f.id_distance_gt.has_value());
      // The dataset has neutral images, so the ground-truth reference drift is measured too.
      if (f.neutral_landmarks != "none") {
        ASSERT_TRUE(f.id_distance_reference.has_value());
        EXPECT_GE(*f.id_distance_reference, 0.0);
      }
      EXPECT_GE(*f.id_distance_gt, 0.0);
      if (f.id_distance) {
        EXPECT_GE(*f.id_distance, 0.0);
        EXPECT_LE(*f.id_cosine, 1.0 + 1e-9);
      }
    }
    EXPECT_EQ(with_id->identity_missing + with_id->tiers[0].id_count + with_id->tiers[1].id_count +
                  with_id->tiers[2].id_count + with_id->tiers[3].id_count,
              static_cast<int>(with_id->frames.size()));
  }
  fs::remove_all(dir);
}

// The training-view fit measures the face where the face is: ground truth that equals the model's
// render inside each training frame's landmark hull and differs strongly outside it scores a face
// PSNR limited only by the 8-bit PNG (about 59 dB), while the full-image PSNR is low. Were the face
// region the whole image, both would be low.
TEST(EvaluateTest, TrainingFitFaceRegionIsTheLandmarkHull) {
  const fs::path dir = TempDir("fit");
  const Executor executor(2);
  const Dataset original = TinySyntheticDataset(dir, executor);
  const std::unique_ptr<Trainer> trainer = TinyTrainer(original, dir, 0);
  const AvatarModel& model = trainer->model();

  fs::copy(dir / "data", dir / "fake", fs::copy_options::recursive);
  Result<Dataset> fake = LoadDataset(dir / "fake");
  ASSERT_TRUE(fake.ok()) << fake.status().message();
  for (const Frame& frame : fake->train) {
    Image image = RenderImage(model, frame.camera, frame.expression, fake->background, executor).color;
    const Image face = FaceRegion(image.width, image.height, *frame.landmarks_2d);
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        if (face.At(x, y, 0) < 0.5f)
          for (int c = 0; c < 3; ++c) image.At(x, y, c) = image.At(x, y, c) < 0.5f ? 1.f : 0.f;
    ASSERT_TRUE(WritePng(fake->ImagePath(frame), image).ok());
  }
  EvalOptions options;  // no renders written
  const Result<EvalResult> result = EvaluateModel(model, *fake, options, EvalNetworks{}, executor, nullptr);
  ASSERT_TRUE(result.ok()) << result.status().message();
  ASSERT_EQ(result->train_fit.frames.size(), fake->train.size());
  for (const TrainFrameFit& f : result->train_fit.frames) {
    EXPECT_GT(f.face_pixels, 0);
    EXPECT_TRUE(f.render_path.empty());
    ASSERT_TRUE(f.psnr.has_value());
    EXPECT_LT(*f.psnr, 15.0) << f.file_path;  // at least 0.5 off on every channel outside the hull
    if (f.face_psnr) {
      EXPECT_GT(*f.face_psnr, 50.0) << f.file_path;  // null: identical (infinite)
    }
  }
  // Only the training views were changed: the test frames' numbers are those of the original.
  const Result<EvalResult> reference =
      EvaluateModel(model, original, options, EvalNetworks{}, executor, nullptr);
  ASSERT_TRUE(reference.ok()) << reference.status().message();
  EXPECT_EQ(result->frames[0].psnr, reference->frames[0].psnr);
  EXPECT_GT(*reference->train_fit.psnr, *result->train_fit.psnr);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace icef::eval
