#include "icef/synth/synthesize.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "icef/face/expression.h"
#include "icef/io/atomic_file.h"
#include "icef/synth/contact_sheet.h"

namespace icef::synth {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("icef_synth_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

SynthOptions Tiny(const fs::path& out, uint64_t seed) {
  SynthOptions o;
  o.out_dir = out;
  o.identity_seed = seed;
  o.num_train = 3;
  o.resolution = 24;
  o.test_views = 2;
  o.novel_per_tier = 1;
  return o;
}

TEST(SynthesizeTest, PlanHasDistinctViewsInRangeAndHonestTiers) {
  SynthOptions o;
  o.out_dir = "unused";
  o.num_train = 10;
  o.test_views = 4;
  o.novel_per_tier = 3;
  const Result<SynthPlan> plan = PlanSynthesis(o);
  ASSERT_TRUE(plan.ok()) << plan.status().message();
  ASSERT_EQ(plan->train_cameras.size(), 10u);
  std::vector<Vec3d> centres;
  for (const Camera& c : plan->train_cameras) {
    const Vec3d d = c.Center().normalized();
    EXPECT_LE(std::abs(std::atan2(d.x(), d.z())) * 180 / M_PI, 35.0 + 1e-9);
    EXPECT_LE(std::abs(std::asin(d.y())) * 180 / M_PI, 15.0 + 1e-9);
    EXPECT_NEAR(c.Center().norm(), 3.5, 1e-9);
    for (const Vec3d& other : centres) EXPECT_GT((other - d).norm(), 1e-3);
    centres.push_back(d);
  }
  std::vector<int> per_tier(4, 0);
  for (const TestExpression& t : plan->test_expressions) {
    EXPECT_DOUBLE_EQ(t.delta, ExpressionDelta(t.beta, plan->train_expressions));
    EXPECT_EQ(t.tier, TierForDelta(t.delta, o.near_threshold, o.far_threshold));
    ++per_tier[static_cast<int>(t.tier)];
    float max_value = 0.f;
    for (float b : t.beta) {
      max_value = std::max(max_value, b);
      EXPECT_GE(b, 0.f);
    }
    if (t.tier == Tier::kFar) {
      EXPECT_GE(max_value, 0.9f);
    }
  }
  EXPECT_EQ(per_tier, (std::vector<int>{10, 3, 3, 3}));
  for (const auto& beta : plan->train_expressions)
    for (float b : beta) EXPECT_LE(b, 0.65f);  // training expressions are moderate
}

TEST(SynthesizeTest, TierForDelta) {
  EXPECT_EQ(TierForDelta(0.0, 0.3, 0.8), Tier::kObserved);
  EXPECT_EQ(TierForDelta(0.3, 0.3, 0.8), Tier::kNear);
  EXPECT_EQ(TierForDelta(0.31, 0.3, 0.8), Tier::kModerate);
  EXPECT_EQ(TierForDelta(0.81, 0.3, 0.8), Tier::kFar);
  EXPECT_DOUBLE_EQ(ExpressionDelta({3.f, 4.f}, {{0.f, 0.f}, {3.f, 5.f}}), 1.0);
}

TEST(SynthesizeTest, BadOptionsAreErrorsNamingTheField) {
  SynthOptions o = Tiny("x", 1);
  o.near_threshold = 0.9;
  EXPECT_NE(o.Validate().message().find("tier thresholds"), std::string::npos);
  o = Tiny("x", 1);
  o.num_train = 0;
  EXPECT_NE(o.Validate().message().find("k:"), std::string::npos);
  o = Tiny("", 1);
  EXPECT_FALSE(o.Validate().ok());
}

TEST(SynthesizeTest, WritesALoadableDeterministicDataset) {
  const fs::path a = TempDir("a"), b = TempDir("b"), c = TempDir("c");
  Dataset written;
  ASSERT_TRUE(SynthesizeDataset(Tiny(a, 5), Executor(2), nullptr, &written).ok());
  ASSERT_TRUE(SynthesizeDataset(Tiny(b, 5), Executor(1), nullptr).ok());
  ASSERT_TRUE(SynthesizeDataset(Tiny(c, 6), Executor(2), nullptr).ok());
  // Same seed, same bytes (JSON and every image); another identity differs.
  int files = 0, differing = 0;
  for (const auto& entry : fs::recursive_directory_iterator(a)) {
    if (!entry.is_regular_file()) continue;
    const fs::path rel = fs::relative(entry.path(), a);
    ++files;
    EXPECT_EQ(*ReadFile(entry.path()), *ReadFile(b / rel)) << rel;
    if (rel.extension() == ".png") differing += *ReadFile(entry.path()) != *ReadFile(c / rel);
  }
  const int images = static_cast<int>(SynthImageCount(Tiny(a, 5)));
  EXPECT_EQ(files, images + 4);  // + transforms_train.json, transforms_test.json, style.json, scene.json
  EXPECT_EQ(differing, images);

  const Result<Dataset> loaded = LoadDataset(a);
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  const Dataset& ds = *loaded;
  EXPECT_EQ(ds.train.size(), 3u);
  EXPECT_EQ(ds.test.size(), static_cast<size_t>((3 + 3) * 2));
  EXPECT_EQ(ds.expression_dim, face::kNumExpressions);
  EXPECT_EQ(ds.expression_names, face::ExpressionNames());
  ASSERT_TRUE(ds.tier_thresholds.has_value());
  std::vector<std::vector<float>> train;
  for (const Frame& f : ds.train) {
    train.push_back(f.expression);
    EXPECT_TRUE(f.landmarks_2d && f.landmarks_3d && f.landmarks_2d_visible);
  }
  for (const Frame& f : ds.test) {
    ASSERT_TRUE(f.delta && f.tier && f.neutral_file_path);
    const double delta = ExpressionDelta(f.expression, train);
    EXPECT_NEAR(*f.delta, delta, 1e-6);  // the JSON's delta agrees with the expressions
    EXPECT_EQ(*f.tier,
              TierForDelta(delta < 1e-9 ? 0.0 : delta, (*ds.tier_thresholds)[0], (*ds.tier_thresholds)[1]));
    EXPECT_TRUE(f.landmarks_2d && f.landmarks_3d && f.landmarks_2d_visible);
    // The neutral of the view keeps its landmarks (eval aligns the neutral reference with them):
    // the same for every frame of the view, and brows, eyes or lips move with the expression.
    ASSERT_TRUE(f.neutral_landmarks_2d && f.neutral_landmarks_3d);
    const Frame& first_of_view = ds.test[(&f - ds.test.data()) % 2];  // frames are expression-major, 2 views
    EXPECT_EQ(*f.neutral_landmarks_2d, *first_of_view.neutral_landmarks_2d);
    double lip_motion = 0;
    for (int i = 17; i < 68; ++i) lip_motion += ((*f.landmarks_3d)[i] - (*f.neutral_landmarks_3d)[i]).norm();
    EXPECT_GT(lip_motion, 1e-4) << f.file_path;
  }
  const Result<Image> sheet = MakeContactSheet(ds, ContactSheetOptions());
  ASSERT_TRUE(sheet.ok()) << sheet.status().message();
  EXPECT_GT(sheet->width, 3 * 96);
  // Several datasets: one row of training frames each.
  const Result<Image> rows = MakeTrainingSheet({ds, ds}, ContactSheetOptions{.tile = 32});
  ASSERT_TRUE(rows.ok()) << rows.status().message();
  EXPECT_EQ(rows->height, 4 + 2 * (32 + 12 + 4));
  EXPECT_EQ(rows->width, 4 + 3 * (32 + 4));
  fs::remove_all(a), fs::remove_all(b), fs::remove_all(c);
}

TEST(SynthesizeTest, RendersTheIdentitysStyleUnlessGenericIsAsked) {
  const fs::path a = TempDir("styled"), b = TempDir("generic");
  SynthOptions styled = Tiny(a, 2), generic = Tiny(b, 2);
  generic.generic_style = true;
  EXPECT_NE(styled.ToString(), generic.ToString());  // a cached dataset of the other kind is not reused
  EXPECT_EQ(SynthIdentity(styled).style, IdentityParams::FromSeed(2).style);
  EXPECT_TRUE(SynthIdentity(generic).style.IsGeneric());
  EXPECT_EQ(SynthIdentity(generic).shape.ToArray(), SynthIdentity(styled).shape.ToArray());
  Dataset ds_a, ds_b;
  face::StyleGap gap_a, gap_b;
  ASSERT_TRUE(SynthesizeDataset(styled, Executor(2), nullptr, &ds_a, &gap_a).ok());
  ASSERT_TRUE(SynthesizeDataset(generic, Executor(2), nullptr, &ds_b, &gap_b).ok());
  EXPECT_GT(gap_a.mean, 0.1);
  EXPECT_EQ(gap_b.mean, 0.0);
  // Landmarks are the styled (or generic) face model's, at the frame's expression.
  const IdentityParams id = IdentityParams::FromSeed(2);
  const face::FaceModel styled_face(id.shape, id.style), generic_face(id.shape);
  for (size_t k = 0; k < ds_a.train.size(); ++k) {
    const auto want_a = styled_face.Landmarks(styled_face.Prepare(ds_a.train[k].expression));
    const auto want_b = generic_face.Landmarks(generic_face.Prepare(ds_b.train[k].expression));
    float diff = 0.f;
    for (int i = 0; i < 68; ++i) {
      EXPECT_EQ((*ds_a.train[k].landmarks_3d)[i], want_a[i]);
      EXPECT_EQ((*ds_b.train[k].landmarks_3d)[i], want_b[i]);
      diff = std::max(diff, (want_a[i] - want_b[i]).norm());
    }
    EXPECT_GT(diff, 1e-3f) << "train frame " << k;  // every training expression shows the style
  }
  // Neutral frames do not depend on the style; expressive ones do.
  EXPECT_EQ(*ReadFile(a / "images" / "test_neutral_000.png"),
            *ReadFile(b / "images" / "test_neutral_000.png"));
  EXPECT_NE(*ReadFile(a / "images" / "train_000.png"), *ReadFile(b / "images" / "train_000.png"));
  // style.json records the style and the gap; the dataset loader ignores it.
  const Result<Json> info = ReadJsonFile(a / kStyleInfoFile);
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ((*info)["identity_seed"], 2);
  EXPECT_EQ((*info)["generic_style"], false);
  EXPECT_EQ((*info)["style"]["jaw_gain"].get<float>(), id.style.jaw_gain);
  EXPECT_EQ((*info)["style"]["smile_gain"][1].get<float>(), id.style.smile_gain[1]);
  EXPECT_DOUBLE_EQ((*info)["style_gap"]["mean"].get<double>(), gap_a.mean);
  EXPECT_EQ((*info)["style_gap"]["per_expression"].size(), static_cast<size_t>(face::kNumExpressions));
  const Result<Json> generic_info = ReadJsonFile(b / kStyleInfoFile);
  ASSERT_TRUE(generic_info.ok());
  EXPECT_EQ((*generic_info)["generic_style"], true);
  EXPECT_TRUE(LoadDataset(a).ok());
  fs::remove_all(a), fs::remove_all(b);
}

}  // namespace
}  // namespace icef::synth
