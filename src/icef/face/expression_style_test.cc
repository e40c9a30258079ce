#include "icef/face/expression_style.h"

#include <gtest/gtest.h>

#include <cmath>

#include "icef/core/rng.h"
#include "icef/face/face_model.h"
#include "icef/face/style_gap.h"

namespace icef::face {
namespace {

std::vector<float> One(int e, float v = 1.f) {
  std::vector<float> b(kNumExpressions, 0.f);
  b[e] = v;
  return b;
}

ShapeParams SomeShape() {
  ShapeParams p;
  p.jaw_width = 1.08f, p.nose_length = 0.93f, p.lip_thickness = 1.2f, p.brow_height = 0.9f,
  p.mouth_width = 1.05f;
  return p;
}

// A style far from the generic one in every field.
ExpressionStyle Strong() {
  ExpressionStyle st;
  st.jaw_gain = 1.3f, st.jaw_hinge_dy = 0.02f, st.jaw_hinge_dz = -0.03f;
  st.smile_gain = {0.7f, 1.2f}, st.smile_width = 1.25f, st.smile_lift = 0.75f, st.smile_corner_shift = 0.015f;
  st.lip_pucker_gain = 1.3f, st.lip_press_gain = 0.7f;
  st.brow_raise_gain = {1.2f, 0.7f}, st.brow_raise_shift = -0.02f, st.brow_furrow_gain = 1.3f;
  st.eye_close_gain = {0.5f, 2.f}, st.cheek_puff_gain = 0.7f;
  return st;
}

TEST(ExpressionStyleTest, FieldsRoundTripByName) {
  const ExpressionStyle strong = Strong();
  const auto fields = strong.Fields();
  ASSERT_EQ(fields.size(), size_t(ExpressionStyle::kNumFields));
  EXPECT_EQ(fields[0].first, "jaw_gain");
  EXPECT_EQ(fields[ExpressionStyle::kNumGains].first, "jaw_hinge_dy");
  ExpressionStyle copy;
  for (const auto& [name, value] : fields) EXPECT_TRUE(copy.SetField(name, value)) << name;
  EXPECT_EQ(copy, strong);
  // Every field is reached: each one set alone makes the style differ from the generic one.
  for (const auto& [name, value] : fields) {
    ExpressionStyle one;
    ASSERT_TRUE(one.SetField(name, value + 0.01f));
    EXPECT_FALSE(one.IsGeneric()) << name;
  }
  EXPECT_FALSE(copy.SetField("jaw_gains", 1.f));
}

TEST(ExpressionStyleTest, DefaultsAreTheGenericStyle) {
  const ExpressionStyle st;
  EXPECT_EQ(st, ExpressionStyle::Generic());
  EXPECT_TRUE(st.IsGeneric());
  EXPECT_TRUE(st.Validate().ok());
  for (int e = 0; e < kNumExpressions; ++e) EXPECT_EQ(st.WeightGain(e), 1.f) << kExpressionNames[e];
  EXPECT_EQ(st.ToString(), "ExpressionStyle(generic)");
  EXPECT_FALSE(Strong().IsGeneric());
  EXPECT_NE(Strong().ToString().find("smile_gain[1]=1.2"), std::string::npos);
}

TEST(ExpressionStyleTest, WeightGainMapsSidesToExpressions) {
  const ExpressionStyle st = Strong();
  EXPECT_EQ(st.WeightGain(kJawOpen), 1.3f);
  EXPECT_EQ(st.WeightGain(kSmileRight), 0.7f);  // index 0 = the subject's right
  EXPECT_EQ(st.WeightGain(kSmileLeft), 1.2f);
  EXPECT_EQ(st.WeightGain(kBrowRaiseRight), 1.2f);
  EXPECT_EQ(st.WeightGain(kBrowRaiseLeft), 0.7f);
  EXPECT_EQ(st.WeightGain(kEyeCloseRight), 0.5f);
  EXPECT_EQ(st.WeightGain(kEyeCloseLeft), 2.f);
  EXPECT_EQ(st.WeightGain(kCheekPuff), 0.7f);
}

TEST(ExpressionStyleTest, ValidateNamesTheBadField) {
  EXPECT_TRUE(Strong().Validate().ok());
  ExpressionStyle st;
  st.smile_gain[1] = 0.1f;
  ASSERT_FALSE(st.Validate().ok());
  EXPECT_NE(st.Validate().message().find("smile_gain[1]"), std::string::npos);
  st = ExpressionStyle();
  st.jaw_hinge_dz = 0.2f;
  ASSERT_FALSE(st.Validate().ok());
  EXPECT_NE(st.Validate().message().find("jaw_hinge_dz"), std::string::npos);
  st = ExpressionStyle();
  st.cheek_puff_gain = std::nanf("");
  EXPECT_FALSE(st.Validate().ok());
  st.cheek_puff_gain = 1.f;
  EXPECT_THROW(FaceModel(SomeShape(),
                         [] {
                           ExpressionStyle bad;
                           bad.brow_furrow_gain = -1.f;
                           return bad;
                         }()),
               InternalError);
}

// The default argument, Generic() and a value-initialised style are the same model, state for
// state and point for point (the byte-identical datasets of `icef synth --generic-style` check
// the same against the pre-style binary; see docs/face_model.md).
TEST(ExpressionStyleTest, GenericStyleIsTheGenericModel) {
  const ShapeParams shape = SomeShape();
  const FaceModel a(shape), b(shape, ExpressionStyle::Generic()), c(shape, ExpressionStyle{});
  EXPECT_TRUE(a.style().IsGeneric());
  Rng rng(11, StreamId("test"));
  for (int trial = 0; trial < 8; ++trial) {
    std::vector<float> beta(kNumExpressions);
    for (float& v : beta) v = static_cast<float>(rng.Uniform(0.0, 1.5));
    const ExpressionState sa = a.Prepare(beta), sb = b.Prepare(beta), sc = c.Prepare(beta);
    EXPECT_EQ(sa.styled, sa.beta);  // every gain is exactly 1
    EXPECT_EQ(sa.jaw_angle, 0.20f * beta[kJawOpen]);
    EXPECT_EQ(sa.lid_upper, sb.lid_upper);
    EXPECT_EQ(sa.cavity_c, sc.cavity_c);
    EXPECT_EQ(sa.cavity_r, sc.cavity_r);
    EXPECT_EQ(sa.step_scale, sb.step_scale);
    for (int i = 0; i < 30; ++i) {
      const Vec3f p(rng.Uniform(-0.25, 0.25), rng.Uniform(-0.4, 0.2), rng.Uniform(0.0, 0.35));
      EXPECT_EQ(a.Warp(p, sa), b.Warp(p, sb));
      EXPECT_EQ(a.Warp(p, sa), c.Warp(p, sc));
      EXPECT_EQ(a.Distance(p, sa), c.Distance(p, sc));
    }
    EXPECT_EQ(a.Landmarks(sa), c.Landmarks(sc));
  }
  // Known behaviour of the generic expressions: a unit blink closes the lid, a unit jaw_open
  // turns the jaw by 0.20 rad.
  const ExpressionState blink = a.Prepare(One(kEyeCloseLeft));
  EXPECT_EQ(blink.lid_upper[1], a.geometry().lid_lower);
  EXPECT_EQ(blink.lid_upper[0], a.geometry().lid_upper_neutral);
  EXPECT_EQ(a.Prepare(One(kJawOpen)).jaw_angle, 0.20f);
}

TEST(ExpressionStyleTest, GainsScaleTheirOwnExpressionOnly) {
  const ShapeParams shape = SomeShape();
  const FaceModel generic(shape), styled(shape, Strong());
  // Neutral geometry and landmarks do not depend on the style.
  EXPECT_EQ(generic.NeutralLandmarks(), styled.NeutralLandmarks());
  const ExpressionState neutral = styled.Prepare(std::vector<float>(kNumExpressions, 0.f));
  EXPECT_TRUE(neutral.neutral);
  // The jaw turns by gain x 0.20 rad per unit.
  EXPECT_FLOAT_EQ(styled.Prepare(One(kJawOpen)).jaw_angle, 1.3f * 0.20f);
  // Eye closure: gain 0.5 closes the right lid half-way at weight 1; gain 2 closes the left lid
  // at weight 0.5, and more weight stays closed.
  const FaceGeometry& g = styled.geometry();
  const float half = g.lid_upper_neutral - 0.5f * (g.lid_upper_neutral - g.lid_lower);
  EXPECT_FLOAT_EQ(styled.Prepare(One(kEyeCloseRight)).lid_upper[0], half);
  EXPECT_FLOAT_EQ(styled.Prepare(One(kEyeCloseLeft, 0.5f)).lid_upper[1], g.lid_lower);
  EXPECT_FLOAT_EQ(styled.Prepare(One(kEyeCloseLeft, 2.f)).lid_upper[1], g.lid_lower);
  // A style with only the right smile changed moves only smile_right's landmarks.
  ExpressionStyle right_only;
  right_only.smile_gain[0] = 1.3f;
  const FaceModel r(shape, right_only);
  for (int e = 0; e < kNumExpressions; ++e) {
    const auto a = generic.Landmarks(generic.Prepare(One(e))), b = r.Landmarks(r.Prepare(One(e)));
    float diff = 0.f;
    for (int i = 0; i < 68; ++i) diff = std::max(diff, (a[i] - b[i]).norm());
    if (e == kSmileRight)
      EXPECT_GT(diff, 0.003f);
    else
      EXPECT_EQ(diff, 0.f) << kExpressionNames[e];
  }
  // The right corner (48) rises higher than the generic one; the left smile is untouched.
  const auto gs = generic.Landmarks(generic.Prepare(One(kSmileRight)));
  const auto rs = r.Landmarks(r.Prepare(One(kSmileRight)));
  EXPECT_GT(rs[48].y(), gs[48].y() + 1e-3f);
}

// A gain acts only through the product of weight and gain: a subject with gain g at weight w and
// one with gain 1 at weight g w have the same geometry, hence the same landmarks, outlines and
// images. No tracker can tell the two apart from what it sees, so a tracked weight equals the
// true one only up to the subject's gain (docs/tracking.md, "What the images cannot tell").
TEST(ExpressionStyleTest, AGainAndItsWeightAreIndistinguishable) {
  const ShapeParams shape = SomeShape();
  const ExpressionStyle strong = Strong();
  ExpressionStyle unit_gains = strong;  // the same hinge, smile shape and offsets, every gain 1
  unit_gains.jaw_gain = unit_gains.lip_pucker_gain = unit_gains.lip_press_gain = unit_gains.brow_furrow_gain =
      unit_gains.cheek_puff_gain = 1.f;
  unit_gains.smile_gain = unit_gains.brow_raise_gain = unit_gains.eye_close_gain = {1.f, 1.f};
  const FaceModel a(shape, strong), b(shape, unit_gains);
  Rng rng(9, StreamId("gain_weight_test"));
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<float> w(kNumExpressions), wg(kNumExpressions);
    for (int e = 0; e < kNumExpressions; ++e) {
      w[e] = rng.UniformDouble() < 0.5 ? static_cast<float>(rng.Uniform(0.1, 1.0)) : 0.f;
      wg[e] = w[e] * strong.WeightGain(e);
    }
    const ExpressionState sa = a.Prepare(w), sb = b.Prepare(wg);
    EXPECT_EQ(a.Landmarks(sa), b.Landmarks(sb)) << "trial " << trial;
    for (int i = 0; i < 200; ++i) {
      const Vec3f x(static_cast<float>(rng.Uniform(-0.3, 0.3)), static_cast<float>(rng.Uniform(-0.45, 0.35)),
                    static_cast<float>(rng.Uniform(-0.2, 0.35)));
      EXPECT_EQ(a.Distance(x, sa), b.Distance(x, sb)) << "trial " << trial << " point " << i;
      EXPECT_EQ(a.Warp(x, sa), b.Warp(x, sb)) << "trial " << trial << " point " << i;
    }
  }
  // The other fields of the style do show: the same weights with the generic style's hinge, smile
  // shape and offsets move the landmarks elsewhere.
  const FaceModel generic(shape);
  std::vector<float> smile_jaw(kNumExpressions, 0.f);
  smile_jaw[kJawOpen] = 0.8f, smile_jaw[kSmileLeft] = 0.8f;
  const auto lb = b.Landmarks(b.Prepare(smile_jaw)), lg = generic.Landmarks(generic.Prepare(smile_jaw));
  float diff = 0.f;
  for (int i = 0; i < 68; ++i) diff = std::max(diff, (lb[i] - lg[i]).norm());
  EXPECT_GT(diff, 0.003f);
}

TEST(ExpressionStyleTest, OffsetsMoveTheWarpCentres) {
  const ShapeParams shape = SomeShape();
  const FaceModel generic(shape);
  // A lower jaw hinge opens the mouth with a different motion; the cavity follows the hinge.
  ExpressionStyle hinge;
  hinge.jaw_hinge_dz = 0.05f;
  const FaceModel h(shape, hinge);
  const auto a = generic.Landmarks(generic.Prepare(One(kJawOpen))), b = h.Landmarks(h.Prepare(One(kJawOpen)));
  EXPECT_GT((a[8] - b[8]).norm(), 1e-3f);
  EXPECT_NE(generic.Prepare(One(kJawOpen)).cavity_r, h.Prepare(One(kJawOpen)).cavity_r);
  // Shifting the brow window outwards raises the outer brow (26) more and the inner (22) less.
  ExpressionStyle brow;
  brow.brow_raise_shift = 0.03f;
  const FaceModel s(shape, brow);
  const auto n = generic.NeutralLandmarks();
  const auto ga = generic.Landmarks(generic.Prepare(One(kBrowRaiseLeft)));
  const auto sa = s.Landmarks(s.Prepare(One(kBrowRaiseLeft)));
  EXPECT_GT(sa[26].y() - n[26].y(), ga[26].y() - n[26].y());
  EXPECT_LT(sa[22].y() - n[22].y(), ga[22].y() - n[22].y());
}

TEST(StyleGapTest, ZeroForTheGenericStyle) {
  const StyleGap gap = MeasureStyleGap(SomeShape(), ExpressionStyle::Generic());
  EXPECT_EQ(gap.mean, 0.0);
  EXPECT_GE(gap.num_measured, 9);  // cheek_puff and brow_furrow may move no landmark
  for (int e = 0; e < kNumExpressions; ++e) {
    if (!std::isnan(gap.per_expression[e])) {
      EXPECT_EQ(gap.per_expression[e], 0.0) << kExpressionNames[e];
    }
  }
  for (int e : {kJawOpen, kSmileLeft, kLipPucker, kBrowRaiseRight, kEyeCloseLeft})
    EXPECT_FALSE(std::isnan(gap.per_expression[e])) << kExpressionNames[e];
  EXPECT_NE(gap.ToString().find("mean=0.000"), std::string::npos);
}

TEST(StyleGapTest, APureGainGivesItsRelativeChange) {
  ExpressionStyle st;
  st.lip_pucker_gain = 1.3f, st.lip_press_gain = 0.7f, st.eye_close_gain = {0.6f, 1.4f};
  const StyleGap gap = MeasureStyleGap(SomeShape(), st);
  // The landmark motion of a bump term is nearly linear in its weight.
  EXPECT_NEAR(gap.per_expression[kLipPucker], 0.3, 0.06);
  EXPECT_NEAR(gap.per_expression[kLipPress], 0.3, 0.06);
  // A weaker blink leaves the lid 40 % open at weight 1; a stronger one is closed like the generic.
  EXPECT_GT(gap.per_expression[kEyeCloseRight], 0.2);
  EXPECT_EQ(gap.per_expression[kEyeCloseLeft], 0.0);
  EXPECT_EQ(gap.per_expression[kJawOpen], 0.0);
  EXPECT_GT(gap.mean, 0.0);
  const StyleGap strong = MeasureStyleGap(SomeShape(), Strong());
  EXPECT_GT(strong.mean, 0.25);
}

}  // namespace
}  // namespace icef::face
