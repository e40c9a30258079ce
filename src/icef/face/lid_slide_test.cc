#include <gtest/gtest.h>

#include <cmath>

#include "icef/face/face_model.h"

namespace icef::face {
namespace {

// A point on the closed upper lid (observation space) maps to a point on the neutral, open lid;
// the exposed eyeball below the lid edge and the skin around the eye do not move.
TEST(LidSlideTest, ClosedLidMapsOntoTheOpenLid) {
  const FaceModel model(ShapeParams::Average());
  const FaceGeometry& g = model.geometry();
  std::vector<float> beta(kNumExpressions, 0.f);
  beta[kEyeCloseLeft] = 1.f;
  const ExpressionState closed = model.Prepare(beta);
  const ExpressionState neutral = model.Prepare(std::vector<float>(kNumExpressions, 0.f));
  const int side = 1;  // the subject's left eye (+x)
  ASSERT_LT(closed.lid_upper[side], g.lid_upper_neutral);
  const float shell = g.eye_r + g.lid_thickness;
  int checked = 0;
  for (float theta = closed.lid_upper[side] + 0.05f; theta < g.lid_upper_neutral; theta += 0.1f) {
    for (float phi : {-0.3f, 0.f, 0.3f}) {
      const Vec3f dir(std::sin(phi), std::cos(phi) * std::sin(theta), std::cos(phi) * std::cos(theta));
      // Just outside the closed lid's cap: the surface there is lid in the observation...
      const Vec3f x = g.eye_c[side] + (shell + 1e-3f) * dir.normalized();
      const FaceModel::Sample obs = model.Evaluate(x, closed);
      ASSERT_EQ(obs.material, Material::kEyelid) << theta;
      // ...and its canonical point lies on the neutral head's lid (open eye), not on the eyeball.
      const Vec3f c = model.PriorWarp(x, closed);
      const FaceModel::Sample can = model.Evaluate(c, neutral);
      EXPECT_EQ(can.material, Material::kEyelid) << theta;
      EXPECT_NEAR(can.distance, obs.distance, 2e-3f) << theta;
      ++checked;
    }
  }
  EXPECT_GT(checked, 10);
  // Eyeball below the closed edge, the other eye, and the cheek are left alone.
  const Vec3f eyeball = g.eye_c[side] + g.eye_r * Vec3f(0.f, std::sin(-0.5f), std::cos(-0.5f));
  EXPECT_LT((model.PriorWarp(eyeball, closed) - model.Warp(eyeball, closed)).norm(), 1e-6f);
  const Vec3f other = g.eye_c[0] + shell * Vec3f(0.f, 0.f, 1.f);
  EXPECT_LT((model.PriorWarp(other, closed) - model.Warp(other, closed)).norm(), 1e-6f);
  const Vec3f cheek(0.12f, g.mouth_y + 0.05f, 0.2f);
  EXPECT_LT((model.PriorWarp(cheek, closed) - model.Warp(cheek, closed)).norm(), 1e-6f);
  // At neutral the prior warp is the identity.
  EXPECT_EQ(model.PriorWarp(cheek, neutral), cheek);
}

}  // namespace
}  // namespace icef::face
