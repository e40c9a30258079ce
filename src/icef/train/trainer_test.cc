#include "icef/train/trainer.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <set>

#include "icef/data/landmark_region.h"
#include "icef/model/render_image.h"
#include "icef/synth/synthesize.h"
#include "icef/testing/tiny_dataset.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

// A small synthetic subject (the procedural head) shared by the tests of this file.
const Dataset& TinySubject() {
  static const Dataset* dataset = [] {
    const fs::path dir = testing::MakeTempDir("trainer_subject");
    synth::SynthOptions o;
    o.out_dir = dir;
    o.identity_seed = 3;
    o.num_train = 3;
    o.resolution = 32;
    o.test_views = 1;
    o.novel_per_tier = 1;
    ICEF_CHECK(synth::SynthesizeDataset(o, Executor(2)).ok());
    auto loaded = LoadDataset(dir);
    ICEF_CHECK(loaded.ok(), loaded.status().message());
    return new Dataset(std::move(loaded).value());
  }();
  return *dataset;
}

RunConfig SmallConfig(const std::string& method) {
  RunConfig c;
  c.model.method = method;
  c.model.static_field.grid.num_levels = 8;
  c.model.static_field.grid.log2_table_size = 14;
  c.model.static_field.grid.finest_resolution = 128;
  c.model.sampler.num_samples = 24;
  c.model.occupancy.resolution = 32;
  c.train.batch_rays = 512;
  c.train.depth_prior_view_rays = 64;  // the default's 1/8 of batch_rays
  c.train.threads = 2;
  c.train.log_every = 10;
  c.train.occupancy_warmup = 32;
  c.train.occupancy_every = 8;
  c.train.checkpoint_every = 0;
  return c;
}

std::string ParamBytes(const AvatarModel& model) {
  const nn::ParameterStore& s = model.store();
  return std::string(reinterpret_cast<const char*>(s.params()), s.size() * sizeof(float));
}

TEST(TrainingDataTest, JitteredRaysStayInsideTheirPixelAndAreDeterministic) {
  auto data = TrainingData::Load(TinySubject());
  ASSERT_TRUE(data.ok()) << data.status().message();
  TrainRays centre, jittered, again;
  RaySampling at_centre, jitter;
  jitter.jitter = true;
  data->SampleBatch(256, 9, 4, at_centre, &centre, Executor(2));
  data->SampleBatch(256, 9, 4, jitter, &jittered, Executor(2));
  data->SampleBatch(256, 9, 4, jitter, &again, Executor(1));  // any thread count: the same rays
  int off_centre = 0;
  for (int r = 0; r < 256; ++r) {
    ASSERT_EQ(centre.frame[r], jittered.frame[r]);  // same pixels and targets, only the ray moves
    EXPECT_EQ(centre.target_rgb[3 * r], jittered.target_rgb[3 * r]);
    const Camera& cam = data->camera(centre.frame[r]);
    const auto c = cam.Project((centre.rays[r].origin + 3.f * centre.rays[r].direction).cast<double>());
    const auto j = cam.Project((jittered.rays[r].origin + 3.f * jittered.rays[r].direction).cast<double>());
    ASSERT_TRUE(c && j);
    const double px = std::floor(c->uv.x()), py = std::floor(c->uv.y());
    EXPECT_NEAR(c->uv.x() - px, 0.5, 1e-3);  // without jitter: the pixel centre
    EXPECT_GE(j->uv.x(), px - 1e-3);
    EXPECT_LE(j->uv.x(), px + 1 + 1e-3);
    EXPECT_GE(j->uv.y(), py - 1e-3);
    EXPECT_LE(j->uv.y(), py + 1 + 1e-3);
    off_centre += std::abs(j->uv.x() - c->uv.x()) > 0.05;
    EXPECT_EQ(jittered.rays[r].direction, again.rays[r].direction);
  }
  EXPECT_GT(off_centre, 128);
}

// The pixel a centre ray of `batch` passes through, as (frame, x, y).
std::array<int, 3> RayPixel(const TrainingData& data, const TrainRays& batch, int r) {
  const Camera& cam = data.camera(batch.frame[r]);
  const auto uv = cam.Project((batch.rays[r].origin + 3.f * batch.rays[r].direction).cast<double>());
  ICEF_CHECK(uv.has_value());
  return {batch.frame[r], static_cast<int>(std::floor(uv->uv.x())), static_cast<int>(std::floor(uv->uv.y()))};
}

TEST(TrainingDataTest, RegionRaysComeFromEachFramesExpressionRegion) {
  const Dataset& dataset = TinySubject();
  auto data = TrainingData::Load(dataset);
  ASSERT_TRUE(data.ok()) << data.status().message();
  // The region pixels are exactly each frame's expression region (its own landmarks, eval's dilation).
  std::vector<Image> regions;
  size_t expected = 0;
  for (const Frame& f : dataset.train) {
    ASSERT_TRUE(f.landmarks_2d.has_value());
    const int w = f.camera.width(), h = f.camera.height();
    regions.push_back(ExpressionRegion(w, h, *f.landmarks_2d, {}, DefaultRegionDilation(w)));
    for (float v : regions.back().pixels) expected += v > 0.f;
  }
  ASSERT_GT(expected, 0u);
  EXPECT_EQ(data->region_pixels().size(), expected);
  const int64_t all = data->PixelIndex(data->num_frames() - 1, 0, 0) + 32 * 32;
  EXPECT_LT(expected, size_t(all / 4));  // the region is a small part of the images

  RaySampling quarter;
  quarter.region_fraction = 0.25;
  TrainRays batch, again, uniform;
  data->SampleBatch(400, 5, 7, quarter, &batch, Executor(2));
  data->SampleBatch(400, 5, 7, quarter, &again, Executor(1));
  data->SampleBatch(400, 5, 7, RaySampling{}, &uniform, Executor(2));
  int in_region = 0, uniform_in_region = 0;
  for (int r = 0; r < 400; ++r) {
    const auto [k, x, y] = RayPixel(*data, batch, r);
    const bool inside = regions[k].At(x, y, 0) > 0.f;
    if (r < 100) {
      EXPECT_TRUE(inside) << "ray " << r << ": frame " << k << " pixel " << x << "," << y;
    }
    in_region += inside;
    const auto [ku, xu, yu] = RayPixel(*data, uniform, r);
    uniform_in_region += regions[ku].At(xu, yu, 0) > 0.f;
    EXPECT_EQ(batch.rays[r].direction, again.rays[r].direction);  // any thread count: the same rays
    EXPECT_EQ(batch.target_rgb[3 * r + 1], again.target_rgb[3 * r + 1]);
  }
  EXPECT_GE(in_region, 100);
  EXPECT_LT(uniform_in_region, 100);  // drawn over all pixels, far fewer land in the region

  // A dataset without landmarks has no region: every ray is drawn over all pixels.
  Dataset bare = dataset;
  for (Frame& f : bare.train) f.landmarks_2d.reset();
  auto bare_data = TrainingData::Load(bare);
  ASSERT_TRUE(bare_data.ok()) << bare_data.status().message();
  EXPECT_TRUE(bare_data->region_pixels().empty());
  TrainRays bare_batch;
  bare_data->SampleBatch(400, 5, 7, quarter, &bare_batch, Executor(2));
  for (int r = 0; r < 400; ++r) EXPECT_EQ(bare_batch.rays[r].direction, uniform.rays[r].direction);
}

TEST(TrainerTest, TrainingLowersLossAndRaisesPsnr) {
  const Dataset& dataset = TinySubject();
  RunConfig config = SmallConfig("icef");
  config.train.steps = 200;
  auto trainer = Trainer::Create(dataset, testing::MakeTempDir("trainer_learns"), config);
  ASSERT_TRUE(trainer.ok()) << trainer.status().message();
  // PSNR of the untrained model on the observed-tier test views.
  int count = 0;
  const auto psnr_before =
      Trainer::MeanTierPsnr((*trainer)->model(), dataset, Tier::kObserved, Executor(2), &count);
  ASSERT_TRUE(psnr_before.has_value());
  std::vector<double> losses;
  auto summary = (*trainer)->Run([&](const TrainProgress& p) { losses.push_back(p.terms.total); }, nullptr);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  ASSERT_EQ(summary->steps, 200);
  ASSERT_TRUE(summary->psnr_observed.has_value());
  double first = 0, last = 0;
  for (int i = 0; i < 20; ++i) first += losses[i], last += losses[losses.size() - 1 - i];
  EXPECT_LT(last, 0.5 * first) << "loss did not fall: " << first / 20 << " -> " << last / 20;
  // The training views are fitted...
  const Frame& f = dataset.train.front();
  const Image gt = CompositeOver(*LoadFrameImage(dataset, f), dataset.background);
  const double train_psnr = PsnrFromMse(MeanSquaredError(
      RenderImage((*trainer)->model(), f.camera, f.expression, dataset.background, Executor(2)).color, gt));
  EXPECT_GT(train_psnr, 18.0);
  // ... and held-out views improve clearly over the untrained model (few-shot generalisation at
  // 32x32 from 3 views after 200 steps is modest; the figure is in the issue notes).
  EXPECT_GT(*summary->psnr_observed, *psnr_before + 5.0)
      << "held-out PSNR " << *psnr_before << " -> " << *summary->psnr_observed;
  std::cout << "held-out PSNR " << *psnr_before << " -> " << *summary->psnr_observed << " dB, training view "
            << train_psnr << " dB\n";
}

TEST(TrainerTest, ResumeContinuesBitIdentically) {
  const Dataset& dataset = TinySubject();
  RunConfig config = SmallConfig("icef");
  config.train.steps = 48;
  config.train.lambda_smooth = 1e-3;  // exercise every loss term
  // Uninterrupted run.
  const fs::path straight_dir = testing::MakeTempDir("trainer_straight");
  auto straight = Trainer::Create(dataset, straight_dir, config);
  ASSERT_TRUE(straight.ok());
  ASSERT_TRUE((*straight)->Run(nullptr, nullptr).ok());
  // Interrupted at step 40 (past the occupancy warm-up), then resumed from the checkpoint.
  const fs::path split_dir = testing::MakeTempDir("trainer_split");
  RunConfig first_half = config;
  auto part = Trainer::Create(dataset, split_dir, first_half);
  ASSERT_TRUE(part.ok());
  std::atomic<bool> stop{false};
  auto summary = (*part)->Run([&](const TrainProgress& p) { stop = p.step >= 40; }, &stop);
  ASSERT_TRUE(summary.ok());
  EXPECT_TRUE(summary->interrupted);
  EXPECT_EQ(summary->steps, 40);
  part->reset();
  auto resumed = Trainer::Resume(dataset, split_dir, std::nullopt, std::nullopt, std::nullopt);
  ASSERT_TRUE(resumed.ok()) << resumed.status().message();
  EXPECT_EQ((*resumed)->step(), 40);
  ASSERT_TRUE((*resumed)->Run(nullptr, nullptr).ok());
  EXPECT_EQ((*resumed)->step(), 48);
  EXPECT_TRUE(ParamBytes((*straight)->model()) == ParamBytes((*resumed)->model()))
      << "resumed training diverged from the uninterrupted run";
  EXPECT_EQ((*straight)->model().occupancy().densities(), (*resumed)->model().occupancy().densities());
}

TEST(TrainerTest, SameSeedSameNumbersDifferentSeedDifferent) {
  const Dataset& dataset = TinySubject();
  RunConfig config = SmallConfig("warp");
  config.train.steps = 12;
  std::string bytes[3];
  for (int run = 0; run < 3; ++run) {
    config.train.seed = run == 2 ? 1 : 0;
    auto t = Trainer::Create(dataset, testing::MakeTempDir("trainer_seed" + std::to_string(run)), config);
    ASSERT_TRUE(t.ok());
    ASSERT_TRUE((*t)->Run(nullptr, nullptr).ok());
    bytes[run] = ParamBytes((*t)->model());
  }
  EXPECT_TRUE(bytes[0] == bytes[1]);
  EXPECT_FALSE(bytes[0] == bytes[2]);
}

// warp and icef-no-id differ only in confidence, which acts at render time: they train the same
// model bit for bit, which is why the bench runs only warp (model/method.h).
TEST(TrainerTest, WarpAndIcefNoIdTrainTheSameModel) {
  const Dataset& dataset = TinySubject();
  std::string bytes[2];
  int i = 0;
  for (const char* method : {"warp", "icef-no-id"}) {
    RunConfig config = SmallConfig(method);
    config.train.steps = 12;
    auto t = Trainer::Create(dataset, testing::MakeTempDir(std::string("trainer_same_") + method), config);
    ASSERT_TRUE(t.ok());
    ASSERT_TRUE((*t)->Run(nullptr, nullptr).ok());
    bytes[i++] = ParamBytes((*t)->model());
  }
  EXPECT_TRUE(bytes[0] == bytes[1]);
}

TEST(TrainerTest, EveryMethodTrainsAndWritesItsModelDirectory) {
  const Dataset& dataset = TinySubject();
  for (Method m : AllMethods()) {
    RunConfig config = SmallConfig(MethodName(m));
    config.train.steps = 6;
    config.train.anneal_steps = 100;  // still annealing when training stops
    const fs::path dir = testing::MakeTempDir(std::string("trainer_method_") + MethodName(m));
    auto t = Trainer::Create(dataset, dir, config);
    ASSERT_TRUE(t.ok()) << MethodName(m);
    auto s = (*t)->Run(nullptr, nullptr);
    ASSERT_TRUE(s.ok()) << s.status().message();
    for (const char* f : {"checkpoint.icef", "config.json", "summary.json", "train_log.jsonl"})
      EXPECT_TRUE(fs::exists(dir / f)) << MethodName(m) << " " << f;
    // The methods on the face model learn their mouth cavity's colour and report it.
    EXPECT_EQ(s->mouth_cavity_colour.has_value(), TraitsOf(m).prior) << MethodName(m);
    if (s->mouth_cavity_colour) {
      for (double c : *s->mouth_cavity_colour) EXPECT_TRUE(c > 0.0 && c < 1.0) << MethodName(m);
    }
    auto loaded = LoadModel(dir, Executor(1));
    ASSERT_TRUE(loaded.ok()) << loaded.status().message();
    EXPECT_EQ(loaded->model->method(), m);
    EXPECT_TRUE(ParamBytes(*loaded->model) == ParamBytes((*t)->model()));
    // The loaded model renders exactly what the trained one does (annealing, occupancy, hull).
    const Frame& f = dataset.test.front();
    const RenderedImage a =
        RenderImage((*t)->model(), f.camera, f.expression, dataset.background, Executor(2));
    const RenderedImage b =
        RenderImage(*loaded->model, f.camera, f.expression, dataset.background, Executor(2));
    EXPECT_EQ(a.color.pixels, b.color.pixels) << MethodName(m);
  }
}

// icef-prior fits the prior shading's light to the training images and keeps it in the model; on
// images too small to fit one it trains unshaded and says why.
TEST(TrainerTest, PriorShadingFitsTheLightOrSaysWhyNot) {
  RunConfig config = SmallConfig("icef-prior");
  config.train.steps = 2;
  const fs::path dir = testing::MakeTempDir("trainer_prior_light");
  auto t = Trainer::Create(TinySubject(), dir, config);
  ASSERT_TRUE(t.ok()) << t.status().message();
  ASSERT_TRUE((*t)->model().prior_light().has_value());
  EXPECT_TRUE((*t)->prior_shading_note().empty());
  // The classic scene's key light: strength 0.72 / 0.38 towards (-0.35, 0.45, 0.82).
  const Vec3f light = *(*t)->model().prior_light();
  EXPECT_GT(light.normalized().dot(Vec3f(-0.35f, 0.45f, 0.82f).normalized()), 0.95f) << light.transpose();
  ASSERT_TRUE((*t)->Run(nullptr, nullptr).ok());
  auto loaded = LoadModel(dir, Executor(1));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  ASSERT_TRUE(loaded->model->prior_light().has_value());
  EXPECT_EQ(*loaded->model->prior_light(), light);

  config.model.prior_shading = false;
  auto off = Trainer::Create(TinySubject(), testing::MakeTempDir("trainer_prior_light_off"), config);
  ASSERT_TRUE(off.ok()) << off.status().message();
  EXPECT_FALSE((*off)->model().prior_light().has_value());
  EXPECT_TRUE((*off)->prior_shading_note().empty());

  const fs::path tiny = testing::MakeTempDir("trainer_prior_light_tiny");
  synth::SynthOptions o;
  o.out_dir = tiny;
  o.num_train = 3;
  o.resolution = 12;
  o.test_views = 1;
  o.novel_per_tier = 1;
  ASSERT_TRUE(synth::SynthesizeDataset(o, Executor(2)).ok());
  auto dataset = LoadDataset(tiny);
  ASSERT_TRUE(dataset.ok()) << dataset.status().message();
  config.model.prior_shading = true;
  auto small = Trainer::Create(*dataset, testing::MakeTempDir("trainer_prior_light_tiny_model"), config);
  ASSERT_TRUE(small.ok()) << small.status().message();
  EXPECT_FALSE((*small)->model().prior_light().has_value());
  EXPECT_NE((*small)->prior_shading_note().find("too few"), std::string::npos)
      << (*small)->prior_shading_note();
  EXPECT_TRUE((*small)->Run(nullptr, nullptr).ok());
}

// train.density_start_steps seeds the fitted head's density before the first step on the
// face-model prior's methods, and says so; with 0 or without the prior the start is the uniform one.
TEST(TrainerTest, DensityStartSeedsTheFittedHeadOnThePriorOnly) {
  auto density_params = [](Trainer& t) {
    std::vector<float> v;
    for (int b = 0; b < t.model().store().num_blocks(); ++b) {
      const nn::ParamBlock& block = t.model().store().block(b);
      if (block.name.find("density") == std::string::npos && block.name.find("grid") == std::string::npos)
        continue;
      v.insert(v.end(), t.model().store().params() + block.offset,
               t.model().store().params() + block.offset + block.size);
    }
    return v;
  };
  for (const std::string method : {"icef-prior", "icef"}) {
    RunConfig config = SmallConfig(method);
    auto plain = Trainer::Create(TinySubject(), testing::MakeTempDir("trainer_density_start_off"), config);
    ASSERT_TRUE(plain.ok()) << plain.status().message();
    EXPECT_TRUE((*plain)->density_start_note().empty());
    config.train.density_start_steps = 3;
    auto seeded = Trainer::Create(TinySubject(), testing::MakeTempDir("trainer_density_start_on"), config);
    ASSERT_TRUE(seeded.ok()) << seeded.status().message();
    const bool prior = method == "icef-prior";
    EXPECT_EQ((*seeded)->density_start_note().find("density start: 3 steps") == 0, prior) << method;
    EXPECT_EQ(density_params(**seeded) != density_params(**plain), prior) << method;
    EXPECT_FALSE(density_params(**plain).empty());
  }
  RunConfig bad = SmallConfig("icef-prior");
  bad.train.density_start_erosion = -1;
  EXPECT_FALSE(bad.Validate().ok());
}

// train.lambda_depth_prior: L_depth enters the loss on the face-model prior only (the icef method
// has no fitted face model to take depths from), and resuming keeps it.
TEST(TrainerTest, DepthPriorActsOnThePriorOnly) {
  for (const std::string method : {"icef-prior", "icef"}) {
    RunConfig config = SmallConfig(method);
    config.train.lambda_depth_prior = 10;
    config.train.checkpoint_every = 0;
    config.train.steps = 3;
    config.train.region_rays = 0.5;      // the targets lie in the expression regions
    config.train.depth_prior_views = 0;  // the training pixels' regions alone (views: below)
    const fs::path dir = testing::MakeTempDir("trainer_depth_prior_" + method);
    auto trainer = Trainer::Create(TinySubject(), dir, config);
    ASSERT_TRUE(trainer.ok()) << trainer.status().message();
    const bool prior = method == "icef-prior";
    for (int step = 0; step < 2; ++step) {
      Result<LossTerms> terms = (*trainer)->Step();
      ASSERT_TRUE(terms.ok()) << terms.status().message();
      EXPECT_EQ(terms->Get("depth") > 0, prior) << method;
    }
    if (!prior) continue;
    // The eyes alone: fewer rays with a target, so another (smaller, still positive) term.
    RunConfig eyes_config = config;
    eyes_config.train.depth_prior_region = "eyes";
    auto eyes = Trainer::Create(TinySubject(), testing::MakeTempDir("trainer_depth_prior_eyes"), eyes_config);
    ASSERT_TRUE(eyes.ok()) << eyes.status().message();
    auto fresh = Trainer::Create(TinySubject(), testing::MakeTempDir("trainer_depth_prior_fresh"), config);
    ASSERT_TRUE(fresh.ok()) << fresh.status().message();
    const Result<LossTerms> eyes_terms = (*eyes)->Step(), all_terms = (*fresh)->Step();
    ASSERT_TRUE(eyes_terms.ok() && all_terms.ok());
    EXPECT_GT(eyes_terms->Get("depth"), 0);
    EXPECT_LT(eyes_terms->Get("depth"), all_terms->Get("depth"));
    // The whole face: more rays with a target (cheeks, nose, chin as well), so a larger term.
    RunConfig face_config = config;
    face_config.train.depth_prior_region = "face";
    auto face = Trainer::Create(TinySubject(), testing::MakeTempDir("trainer_depth_prior_face"), face_config);
    ASSERT_TRUE(face.ok()) << face.status().message();
    const Result<LossTerms> face_terms = (*face)->Step();
    ASSERT_TRUE(face_terms.ok());
    EXPECT_GT(face_terms->Get("depth"), all_terms->Get("depth"));
    ASSERT_TRUE((*trainer)->SaveCheckpoint().ok());
    auto resumed = Trainer::Resume(TinySubject(), dir, std::nullopt, std::nullopt, std::nullopt);
    ASSERT_TRUE(resumed.ok()) << resumed.status().message();
    Result<LossTerms> terms = (*resumed)->Step();
    ASSERT_TRUE(terms.ok()) << terms.status().message();
    EXPECT_GT(terms->Get("depth"), 0);
  }
  RunConfig bad = SmallConfig("icef-prior");
  bad.train.lambda_depth_prior = -1;
  EXPECT_FALSE(bad.Validate().ok());
  bad = SmallConfig("icef-prior");
  bad.train.depth_prior_region = "nose";
  EXPECT_FALSE(bad.Validate().ok());
  bad = SmallConfig("icef-prior");
  bad.train.depth_prior_window = -0.01;
  EXPECT_FALSE(bad.Validate().ok());
  bad = SmallConfig("icef-prior");
  bad.train.depth_prior_reach = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(bad.Validate().ok());
  bad = SmallConfig("icef-prior");
  bad.train.lambda_occlusion_prior = -1e-4;
  EXPECT_FALSE(bad.Validate().ok());
  bad = SmallConfig("icef-prior");
  bad.train.depth_prior_views = -1;
  EXPECT_FALSE(bad.Validate().ok());
  bad = SmallConfig("icef-prior");
  bad.train.depth_prior_view_rays = -5;
  EXPECT_FALSE(bad.Validate().ok());
  bad = SmallConfig("icef-prior");
  bad.train.depth_prior_view_yaw = 120;
  EXPECT_FALSE(bad.Validate().ok());
  bad = SmallConfig("icef-prior");
  bad.train.depth_prior_view_pitch = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(bad.Validate().ok());
  bad = SmallConfig("icef-prior");
  bad.train.depth_prior_view_region = "eyes";
  const Status view_region = bad.Validate();
  ASSERT_FALSE(view_region.ok());
  EXPECT_NE(view_region.message().find("train.depth_prior_view_region"), std::string::npos)
      << view_region.message();
  bad.train.depth_prior_view_region = "face";
  EXPECT_TRUE(bad.Validate().ok());
  bad.train.depth_prior_view_region = "upper";
  EXPECT_TRUE(bad.Validate().ok());
}

// train.depth_prior_views: the trainer builds the unseen-view pool for the prior alone, each step
// appends depth_prior_view_rays of its rays after the pixel rays, and the depth term then acts
// with no pixel ray holding a target.
TEST(TrainerTest, UnseenViewRaysJoinTheDepthPrior) {
  for (const std::string method : {"icef-prior", "icef"}) {
    RunConfig config = SmallConfig(method);
    config.train.lambda_depth_prior = 10;
    config.train.depth_prior_region = "eyes";
    config.train.region_rays = 0;
    config.train.depth_prior_views = 2;
    config.train.depth_prior_view_rays = 64;
    config.train.checkpoint_every = 0;
    config.train.steps = 2;
    auto trainer =
        Trainer::Create(TinySubject(), testing::MakeTempDir("trainer_view_rays_" + method), config);
    ASSERT_TRUE(trainer.ok()) << trainer.status().message();
    const bool prior = method == "icef-prior";
    EXPECT_EQ((*trainer)->num_view_rays() > 0, prior) << method;
    if (!prior) continue;
    RunConfig none = config;
    none.train.depth_prior_views = 0;
    auto without = Trainer::Create(TinySubject(), testing::MakeTempDir("trainer_view_rays_none"), none);
    ASSERT_TRUE(without.ok());
    EXPECT_EQ((*without)->num_view_rays(), 0u);
    const Result<LossTerms> with_terms = (*trainer)->Step(), without_terms = (*without)->Step();
    ASSERT_TRUE(with_terms.ok() && without_terms.ok());
    EXPECT_GT(with_terms->Get("depth"), without_terms->Get("depth"));
    // The pixel rays are those of the run without views: the same photo term.
    EXPECT_DOUBLE_EQ(with_terms->Get("photo"), without_terms->Get("photo"));
  }
}

TEST(TrainingDataTest, ViewRaysFollowThePixelRays) {
  auto data = TrainingData::Load(TinySubject());
  ASSERT_TRUE(data.ok()) << data.status().message();
  std::vector<ViewRay> pool;
  for (int i = 0; i < 10; ++i)
    pool.push_back(
        ViewRay{Ray{Vec3f(0.1f * i, 0, 3), Vec3f(0, 0, -1)}, int32_t(i % data->num_frames()), 2.f + i});
  RaySampling how;
  how.view_rays = 16;
  TrainRays plain, with_pool, again;
  data->SampleBatch(100, 4, 2, how, &plain, Executor(2));  // no pool: no view rays
  EXPECT_EQ(plain.rays.size(), 100u);
  EXPECT_EQ(plain.NumPhotoRays(), 100);
  data->SetViewRays(pool);
  data->SampleBatch(100, 4, 2, how, &with_pool, Executor(2));
  data->SampleBatch(100, 4, 2, how, &again, Executor(1));
  ASSERT_EQ(with_pool.rays.size(), 116u);
  EXPECT_EQ(with_pool.NumPhotoRays(), 100);
  ASSERT_EQ(with_pool.depth_target.size(), 116u);
  for (int r = 0; r < 100; ++r) {
    EXPECT_EQ(with_pool.rays[r].direction, plain.rays[r].direction);
    EXPECT_EQ(with_pool.target_rgb[3 * r], plain.target_rgb[3 * r]);
    EXPECT_TRUE(std::isnan(with_pool.depth_target[r]));  // no depth targets set on the pixels
  }
  std::set<int> drawn;
  for (int r = 100; r < 116; ++r) {
    const int i = int(std::lround(with_pool.depth_target[r] - 2.f));
    ASSERT_GE(i, 0);
    ASSERT_LT(i, 10);
    drawn.insert(i);
    EXPECT_EQ(with_pool.rays[r].origin, pool[i].ray.origin);
    EXPECT_EQ(with_pool.frame[r], pool[i].frame);
    EXPECT_EQ(with_pool.rays[r].origin, again.rays[r].origin);  // any thread count
  }
  EXPECT_GT(drawn.size(), 4u);
  how.view_rays = 0;
  data->SampleBatch(100, 4, 2, how, &again, Executor(2));
  EXPECT_EQ(again.rays.size(), 100u);
  EXPECT_EQ(again.photo_rays, -1);
}

// train.start_trials tries that many initialisations for start_trial_steps steps and trains the
// one with the lowest late batch loss from the start: the same choice every time, and trial 0 is
// the run's own initialisation.
TEST(TrainerTest, StartTrialsKeepTheBestInitialisationDeterministically) {
  RunConfig config = SmallConfig("icef");
  auto plain = Trainer::Create(TinySubject(), testing::MakeTempDir("trainer_trials_plain"), config);
  ASSERT_TRUE(plain.ok()) << plain.status().message();
  EXPECT_TRUE((*plain)->start_trials_note().empty());
  const std::string plain_params = ParamBytes((*plain)->model());
  config.train.start_trials = 3;
  config.train.start_trial_steps = 8;
  auto a = Trainer::Create(TinySubject(), testing::MakeTempDir("trainer_trials_a"), config);
  auto b = Trainer::Create(TinySubject(), testing::MakeTempDir("trainer_trials_b"), config);
  ASSERT_TRUE(a.ok() && b.ok());
  const std::string& note = (*a)->start_trials_note();
  EXPECT_EQ(note, (*b)->start_trials_note());
  for (const char* part : {"start trials: batch loss over steps 6-8 of trial 0 ", ", trial 1 ", ", trial 2 "})
    EXPECT_NE(note.find(part), std::string::npos) << note;
  EXPECT_EQ((*a)->step(), 0);  // the trials' steps are not the run's
  EXPECT_TRUE(ParamBytes((*a)->model()) == ParamBytes((*b)->model()));
  // The kept trial is the one with the lowest loss in the note; trial 0 is the plain initialisation.
  std::vector<double> losses;
  for (int t = 0; t < 3; ++t) {
    const std::string key = "trial " + std::to_string(t) + " ";
    losses.push_back(std::stod(note.substr(note.find(key) + key.size())));
  }
  const int best = int(std::min_element(losses.begin(), losses.end()) - losses.begin());
  EXPECT_NE(note.find("training starts from trial " + std::to_string(best) + "'s"), std::string::npos)
      << note;
  EXPECT_EQ(ParamBytes((*a)->model()) == plain_params, best == 0) << note;
  config.train.start_trials = 0;
  EXPECT_FALSE(config.Validate().ok());
}

TEST(RunConfigTest, ParentsOverridesAndStrictKeys) {
  const fs::path dir = testing::MakeTempDir("run_config");
  std::ofstream(dir / "base.json")
      << R"({"model": {"method": "warp", "sampler": {"num_samples": 40}}, "train": {"steps": 7}})";
  std::ofstream(dir / "child.json") << R"({"parent": "base.json", "train": {"steps": 9, "lambda_id": 0.5}})";
  auto c = RunConfig::FromFile(dir / "child.json");
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->model.method, "warp");
  EXPECT_EQ(c->model.sampler.num_samples, 40);
  EXPECT_EQ(c->train.steps, 9);
  EXPECT_EQ(c->train.lambda_id, 0.5);
  ASSERT_TRUE(c->ApplyOverride("train.batch_rays=1024").ok());
  EXPECT_EQ(c->train.batch_rays, 1024);
  ASSERT_TRUE(c->ApplyOverride("model.method=nerface").ok());
  EXPECT_EQ(c->model.method, "nerface");
  auto bad = c->ApplyOverride("train.lambda_idd=1");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("lambda_idd"), std::string::npos);
  EXPECT_NE(bad.message().find("valid keys"), std::string::npos);
  EXPECT_FALSE(c->ApplyOverride("model.method=icef2").ok());
  EXPECT_FALSE(c->ApplyOverride("train.lambda_id=-1").ok());
  EXPECT_EQ(c->train.lambda_id, 0.5);  // a rejected override changes nothing
  for (const char* share : {"train.region_rays=1.5", "train.region_rays=-0.1"}) {
    auto out_of_range = c->ApplyOverride(share);
    ASSERT_FALSE(out_of_range.ok()) << share;
    EXPECT_NE(out_of_range.message().find("region_rays"), std::string::npos) << out_of_range.message();
  }
  ASSERT_TRUE(c->ApplyOverride("train.region_rays=0").ok());
  EXPECT_EQ(c->train.region_rays, 0.0);
  std::ofstream(dir / "typo.json") << R"({"trian": {}})";
  EXPECT_FALSE(RunConfig::FromFile(dir / "typo.json").ok());
  std::ofstream(dir / "nan.json") << R"({"train": {"lambda_id": NaN}})";
  auto nan = RunConfig::FromFile(dir / "nan.json");
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.status().message().find("lambda_id"), std::string::npos);
  std::ofstream(dir / "loop.json") << R"({"parent": "loop.json"})";
  EXPECT_FALSE(RunConfig::FromFile(dir / "loop.json").ok());
  // The resolved config round-trips through JSON.
  auto back = RunConfig::FromJson(c->ToJson(), "mem");
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->Hash(), c->Hash());
  EXPECT_NE(ConfigDocumentation().find("| `lambda_id` | `1.0` |"), std::string::npos);
}

}  // namespace
}  // namespace icef
