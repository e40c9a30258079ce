#include "icef/data/frame_coverage.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "icef/data/dataset.h"

namespace icef {
namespace {

CoverageCandidate At(double yaw_deg, std::vector<float> expression) {
  CoverageCandidate c;
  const double a = yaw_deg * std::numbers::pi / 180;
  c.view_direction = Vec3d(std::sin(a), 0, std::cos(a));
  c.expression = std::move(expression);
  return c;
}

TEST(FrameCoverageTest, StartsFrontalNeutralThenSpreads) {
  // Frames of a slow head turn with one smile: the frontal neutral one first, then the extremes.
  std::vector<CoverageCandidate> c;
  for (int i = 0; i < 9; ++i) c.push_back(At(-40 + 10 * i, {0.f, 0.f}));
  c[3].expression = {1.5f, 0.f};  // -10 degrees, a wide smile
  const std::vector<int> chosen = ChooseCoverageFrames(c, 4);
  ASSERT_EQ(chosen.size(), 4u);
  EXPECT_EQ(chosen[0], 4);  // 0 degrees, neutral
  // Then the farthest: the turns at +-40 degrees (2.6 units) before the smile (1.64 units away).
  EXPECT_TRUE((chosen[1] == 0 && chosen[2] == 8) || (chosen[1] == 8 && chosen[2] == 0));
  EXPECT_EQ(chosen[3], 3);  // the smile: farther than the turns at +-20 degrees (1.33 units)
}

TEST(FrameCoverageTest, NestedAndDeterministic) {
  std::vector<CoverageCandidate> c;
  for (int i = 0; i < 12; ++i) c.push_back(At(7.0 * ((i * 5) % 12) - 35, {0.1f * (i % 4), 0.05f * (i % 3)}));
  const std::vector<int> five = ChooseCoverageFrames(c, 5);
  const std::vector<int> three = ChooseCoverageFrames(c, 3);
  EXPECT_EQ(std::vector<int>(five.begin(), five.begin() + 3), three);
  EXPECT_EQ(ChooseCoverageFrames(c, 5), five);
  EXPECT_EQ(ChooseCoverageFrames(c, 12).size(), 12u);
}

TEST(FrameCoverageTest, BlinksAndBlurredFramesOnlyWhenNeeded) {
  std::vector<CoverageCandidate> c = {At(0, {0.f}), At(30, {0.f}), At(-30, {0.f}), At(10, {0.f})};
  c[1].blink = true;
  c[2].sharpness = 0.2;
  std::vector<int> chosen = ChooseCoverageFrames(c, 2);
  EXPECT_EQ(chosen, (std::vector<int>{0, 3}));
  chosen = ChooseCoverageFrames(c, 4);  // everything, the preferred ones first
  EXPECT_EQ(std::vector<int>(chosen.begin(), chosen.begin() + 2), (std::vector<int>{0, 3}));
  CoverageOptions allow;
  allow.allow_blink = true;
  EXPECT_EQ(ChooseCoverageFrames(c, 2, allow), (std::vector<int>{0, 1}));
}

TEST(FrameCoverageTest, CandidateOfFrameReadsCameraAndBlink) {
  Frame f;
  Mat4d pose = Mat4d::Identity();
  pose.block<3, 1>(0, 3) = Vec3d(0, 0, 2);
  f.camera = Camera(Intrinsics{}, pose);
  f.expression = {0.f, 0.9f};
  const CoverageCandidate c = CandidateOfFrame(f, {"jaw_open", "eye_close_left"});
  EXPECT_NEAR(c.view_direction.z(), 1.0, 1e-12);
  EXPECT_TRUE(c.blink);
  EXPECT_FALSE(CandidateOfFrame(f, {"jaw_open", "smile_left"}).blink);
}

}  // namespace
}  // namespace icef
