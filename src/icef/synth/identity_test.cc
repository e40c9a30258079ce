#include "icef/synth/identity.h"

#include <gtest/gtest.h>

#include <cmath>

#include "icef/core/rng.h"
#include "icef/face/face_model.h"
#include "icef/face/style_gap.h"

namespace icef::synth {
namespace {

using face::ExpressionState;
using face::FaceModel;
using face::kNumExpressions;

std::vector<float> One(int e, float v) {
  std::vector<float> b(kNumExpressions, 0.f);
  b[e] = v;
  return b;
}

TEST(IdentityTest, TheStyleComesFromItsOwnStream) {
  for (uint64_t seed : {1, 2, 3, 17}) {
    const IdentityParams id = IdentityParams::FromSeed(seed);
    EXPECT_EQ(id.style, DrawExpressionStyle(seed));
    EXPECT_FALSE(id.style.IsGeneric());
    // The shape is still the first 13 draws of Rng(seed, "synth.identity") (the stream the style
    // does not touch; the albedo draws follow in the same stream).
    Rng rng(seed, StreamId("synth.identity"));
    EXPECT_EQ(id.shape.head_width, static_cast<float>(rng.Uniform(0.90, 1.10)));
    EXPECT_EQ(id.shape.head_height, static_cast<float>(rng.Uniform(0.92, 1.08)));
  }
  EXPECT_NE(DrawExpressionStyle(1), DrawExpressionStyle(2));
  EXPECT_TRUE(IdentityParams::Average().style.IsGeneric());
  EXPECT_NE(IdentityParams::FromSeed(1).ToString().find("ExpressionStyle(jaw_gain="), std::string::npos);
}

// Every drawn style is valid, inside the documented ranges, and keeps the face model well behaved:
// finite landmarks inside the head's box at weights 0-2, and a warp that InverseWarp inverts.
TEST(IdentityTest, StylesOfSeeds1To20AreValidAndWellBehaved) {
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const IdentityParams id = IdentityParams::FromSeed(seed);
    const face::ExpressionStyle& st = id.style;
    ASSERT_TRUE(st.Validate().ok()) << seed << ": " << st.Validate().message();
    for (int e = 0; e < kNumExpressions; ++e) {
      EXPECT_GE(st.WeightGain(e), 0.65f * 0.75f - 1e-6f) << seed << " " << face::kExpressionNames[e];
      EXPECT_LE(st.WeightGain(e), 1.45f) << seed << " " << face::kExpressionNames[e];
    }
    EXPECT_LE(std::max(st.smile_gain[0], st.smile_gain[1]), 1.2f);
    EXPECT_LE(std::max(st.brow_raise_gain[0], st.brow_raise_gain[1]), 1.2f);
    EXPECT_LE(st.jaw_gain, 1.3f);
    EXPECT_LE(std::abs(st.jaw_hinge_dz), 0.04f);
    EXPECT_LE(std::abs(st.brow_raise_shift), 0.025f);

    const FaceModel face(id.shape, st);
    auto in_box = [&](const std::vector<float>& beta, const std::string& what) {
      for (const Vec3f& p : face.Landmarks(face.Prepare(beta)))
        ASSERT_TRUE(p.allFinite() && face.Bounds().Contains(p)) << "seed " << seed << " " << what;
    };
    for (float w : {0.f, 1.f, 2.f})
      in_box(std::vector<float>(kNumExpressions, w), "all at " + std::to_string(w));
    for (int e = 0; e < kNumExpressions; ++e)
      for (float w : {0.5f, 1.f, 1.5f, 2.f}) in_box(One(e, w), face::kExpressionNames[e] + std::to_string(w));

    // As the generic model's test: InverseWarp finds a true preimage near the face.
    Rng rng(seed, StreamId("test.style_warp"));
    for (int trial = 0; trial < 3; ++trial) {
      std::vector<float> beta(kNumExpressions);
      for (float& b : beta) b = static_cast<float>(rng.Uniform(0.0, 1.5));
      const ExpressionState s = face.Prepare(beta);
      for (int i = 0; i < 25; ++i) {
        const Vec3f p(rng.Uniform(-0.2, 0.2), rng.Uniform(-0.35, 0.15), rng.Uniform(0.15, 0.32));
        EXPECT_LT((face.Warp(face.InverseWarp(p, s), s) - p).norm(), 1e-4f) << "seed " << seed;
      }
    }
    // On the expressed surface, InverseWarp(Warp(x)) = x for every window term at weight 1 (the
    // jaw is left out: its transition band between the lips folds, in the generic model too).
    for (int e = 1; e < kNumExpressions; ++e) {
      const ExpressionState s = face.Prepare(One(e, 1.f));
      for (float px = -0.2f; px <= 0.2f; px += 0.04f)
        for (float py = -0.36f; py <= 0.18f; py += 0.03f) {
          Ray ray;
          ray.origin = Vec3f(px, py, 1.f);
          ray.direction = Vec3f(0.f, 0.f, -1.f);
          const float t = face.Trace(ray, 0.f, 1.2f, s);
          if (t < 0.f) continue;
          const Vec3f x = ray.At(t);
          EXPECT_LT((face.InverseWarp(face.Warp(x, s), s) - x).norm(), 1e-4f)
              << "seed " << seed << " " << face::kExpressionNames[e];
        }
    }
  }
}

// The styles differ clearly from the generic one (docs/face_model.md has the table per seed).
TEST(IdentityTest, StyleGapOfSeeds1To3) {
  double sum = 0.0;
  for (uint64_t seed : {1, 2, 3}) {
    const IdentityParams id = IdentityParams::FromSeed(seed);
    const face::StyleGap gap = face::MeasureStyleGap(id.shape, id.style);
    EXPECT_GE(gap.mean, 0.2) << "seed " << seed << ": " << gap.ToString();
    EXPECT_GE(gap.num_measured, 9);
    sum += gap.mean;
  }
  EXPECT_GE(sum / 3.0, 0.25);
}

}  // namespace
}  // namespace icef::synth
