#include "icef/field/symmetry_plane.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace icef {
namespace {

// 68 landmarks mirror-symmetric about `plane`: random points for indices 0..67, then each mirror
// pair's second index replaced by the reflection of the first and midline points projected onto
// the plane. Pairs follow the iBUG layout (jaw i <-> 16-i, brows, nose, eyes, mouth).
std::vector<Vec3f> SymmetricLandmarks(const SymmetryPlane& plane, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  std::vector<Vec3f> p(68);
  for (Vec3f& x : p) x = Vec3f(u(rng), u(rng), u(rng));
  const int pairs[][2] = {{0, 16},  {1, 15},  {2, 14},  {3, 13},  {4, 12},  {5, 11},  {6, 10},
                          {7, 9},   {17, 26}, {18, 25}, {19, 24}, {20, 23}, {21, 22}, {31, 35},
                          {32, 34}, {36, 45}, {37, 44}, {38, 43}, {39, 42}, {40, 47}, {41, 46}};
  // Keep the "right" points on one side so the pairs are well separated.
  for (const auto& pr : pairs) {
    Vec3f& a = p[pr[0]];
    const float side = plane.normal().dot(a) - plane.offset();
    a += (0.3f - side + 0.5f * std::abs(u(rng))) * plane.normal();
    p[pr[1]] = plane.ReflectPoint(a);
  }
  for (int m : {8, 27, 28, 29, 30, 33}) p[m] = 0.5f * (p[m] + plane.ReflectPoint(p[m]));
  return p;
}

TEST(SymmetryPlaneTest, RecoversThePlaneOfSymmetricLandmarks) {
  for (uint32_t seed = 1; seed <= 5; ++seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> g;
    const SymmetryPlane truth(Vec3f(g(rng), g(rng), g(rng)), 0.7f * g(rng));
    const Result<SymmetryPlane> fit = SymmetryPlane::FromLandmarks(SymmetricLandmarks(truth, seed));
    ASSERT_TRUE(fit.ok()) << fit.status().message();
    const float sign = fit->normal().dot(truth.normal()) > 0 ? 1.f : -1.f;
    EXPECT_NEAR((sign * fit->normal() - truth.normal()).norm(), 0.f, 1e-4f) << seed;
    EXPECT_NEAR(sign * fit->offset(), truth.offset(), 1e-4f) << seed;
    EXPECT_LT(fit->residual(), 1e-4f) << seed;
  }
}

TEST(SymmetryPlaneTest, NormalPointsFromRightToLeftLandmarks) {
  const SymmetryPlane truth(Vec3f(1, 0, 0), 0.f);
  const std::vector<Vec3f> p = SymmetricLandmarks(truth, 3);  // index 0 side has n.x > 0
  const Result<SymmetryPlane> fit = SymmetryPlane::FromLandmarks(p);
  ASSERT_TRUE(fit.ok());
  EXPECT_LT(fit->normal().dot(p[0] - p[16]), 0.f);
}

TEST(SymmetryPlaneTest, ResidualMeasuresAsymmetry) {
  const SymmetryPlane truth(Vec3f(0, 0, 1), 0.2f);
  std::vector<Vec3f> p = SymmetricLandmarks(truth, 4);
  const Vec3f eye_r = (p[36] + p[39]) * 0.5f, eye_l = (p[42] + p[45]) * 0.5f;
  const float iod = (eye_l - eye_r).norm();
  p[0] += Vec3f(0, 0.1f * iod, 0);  // one pair off by a tenth of the inter-ocular distance
  const Result<SymmetryPlane> fit = SymmetryPlane::FromLandmarks(p);
  ASSERT_TRUE(fit.ok());
  EXPECT_GT(fit->residual(), 0.01f);
  EXPECT_LT(fit->residual(), 0.1f);
}

TEST(SymmetryPlaneTest, ReflectionIsAnInvolutionThatFixesThePlane) {
  const SymmetryPlane plane(Vec3f(0.3f, -0.2f, 0.9f), 0.4f);
  const Vec3f x(0.1f, 2.f, -0.5f), d = Vec3f(0.6f, 0.8f, 0.f);
  EXPECT_NEAR((plane.ReflectPoint(plane.ReflectPoint(x)) - x).norm(), 0.f, 1e-6f);
  EXPECT_NEAR((plane.ReflectDirection(plane.ReflectDirection(d)) - d).norm(), 0.f, 1e-6f);
  EXPECT_NEAR(plane.ReflectDirection(d).norm(), 1.f, 1e-6f);
  const Vec3f on = x - (plane.normal().dot(x) - plane.offset()) * plane.normal();
  EXPECT_NEAR((plane.ReflectPoint(on) - on).norm(), 0.f, 1e-6f);
  // The midpoint of x and its mirror image lies on the plane.
  EXPECT_NEAR(plane.normal().dot(0.5f * (x + plane.ReflectPoint(x))), plane.offset(), 1e-6f);
}

TEST(SymmetryPlaneTest, RejectsBadLandmarks) {
  std::vector<Vec3f> p = SymmetricLandmarks(SymmetryPlane(Vec3f(1, 0, 0), 0.f), 5);
  EXPECT_FALSE(SymmetryPlane::FromLandmarks(std::span(p).first(67)).ok());
  p[40].x() = std::numeric_limits<float>::quiet_NaN();
  const Result<SymmetryPlane> nan = SymmetryPlane::FromLandmarks(p);
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.status().message().find("landmark 40"), std::string::npos);
  const std::vector<Vec3f> flat(68, Vec3f(0.1f, 0.2f, 0.3f));
  EXPECT_FALSE(SymmetryPlane::FromLandmarks(flat).ok());
}

}  // namespace
}  // namespace icef
