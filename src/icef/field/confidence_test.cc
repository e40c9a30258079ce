#include "icef/field/confidence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace icef {
namespace {

ExpressionConfidence Make(double lambda) {
  ConfidenceOptions o;
  o.lambda = lambda;
  return *ExpressionConfidence::Create({{0, 0, 0}, {1, 0, 0}, {0, 2, 0}}, o);
}

TEST(ConfidenceTest, KappaIsOneAtEveryTrainingExpression) {
  const ExpressionConfidence c = Make(0.5);
  for (int k = 0; k < 3; ++k) {
    const NearestExpression n = c.Nearest(c.observed(k));
    EXPECT_EQ(n.index, k);
    EXPECT_EQ(n.delta, 0.0);
    EXPECT_EQ(n.kappa, 1.0);
  }
}

TEST(ConfidenceTest, NearestIndexAndDistance) {
  const ExpressionConfidence c = Make(0.5);
  const std::vector<float> beta = {0.9f, 0.3f, 0.4f};
  const NearestExpression n = c.Nearest(beta);
  EXPECT_EQ(n.index, 1);
  EXPECT_NEAR(n.delta, std::sqrt(0.01 + 0.09 + 0.16), 1e-6);
  EXPECT_NEAR(n.kappa, std::exp(-n.delta / 0.5), 1e-12);
  // Brute force over the three candidates agrees.
  double best = 1e9;
  for (int k = 0; k < 3; ++k) {
    double sq = 0;
    for (int j = 0; j < 3; ++j) sq += (beta[j] - c.observed(k)[j]) * (beta[j] - c.observed(k)[j]);
    best = std::min(best, std::sqrt(sq));
  }
  EXPECT_NEAR(n.delta, best, 1e-6);
}

TEST(ConfidenceTest, KappaDecreasesToZeroAsDeltaGrows) {
  const ExpressionConfidence c = Make(0.5);
  double previous = 1.0;
  for (float s : {0.1f, 0.5f, 1.0f, 3.0f, 10.0f}) {
    const NearestExpression n = c.Nearest(std::vector<float>{-s, 0, 0});  // nearest: the origin
    EXPECT_EQ(n.index, 0);
    EXPECT_NEAR(n.delta, s, 1e-6);
    EXPECT_LT(n.kappa, previous);
    previous = n.kappa;
  }
  EXPECT_LT(previous, 1e-8);
  EXPECT_NEAR(ConfidenceFromDistance(0.5, 0.5), std::exp(-1.0), 1e-15);
}

TEST(ConfidenceTest, TiesGoToTheLowestIndex) {
  const ExpressionConfidence c = Make(1.0);
  EXPECT_EQ(c.Nearest(std::vector<float>{0.5f, 0, 0}).index, 0);
}

TEST(ConfidenceTest, ValidatesInputs) {
  ConfidenceOptions bad;
  bad.lambda = 0;
  EXPECT_FALSE(bad.Validate().ok());
  bad.lambda = -1;
  EXPECT_FALSE(ExpressionConfidence::Create({{0.f}}, bad).ok());
  EXPECT_FALSE(ExpressionConfidence::Create({}, ConfidenceOptions()).ok());
  EXPECT_FALSE(ExpressionConfidence::Create({{0.f, 1.f}, {0.f}}, ConfidenceOptions()).ok());
  EXPECT_FALSE(ExpressionConfidence::Create({{NAN}}, ConfidenceOptions()).ok());
  const ExpressionConfidence c = Make(1.0);
  EXPECT_THROW(c.Nearest(std::vector<float>{0.f}), InternalError);
}

}  // namespace
}  // namespace icef
