// The harness must fail a wrong gradient, not only pass a right one.
#include "icef/testing/gradient_check.h"

#include <gtest/gtest.h>

namespace icef::testing {
namespace {

// loss(p) = sum_i c_i p_i^2 / 2 + |p_0 - kink| (by default a kink inside the stencil around p_0 = 0.3,
// off its centre: a centred kink cancels out of central differences).
struct Quadratic {
  double kink = 0.3003;
  std::vector<float> p = {0.3f, -0.5f, 0.8f, 1.2f, -0.1f, 0.6f, -0.9f, 0.4f};
  std::vector<double> c = {1, 2, 3, 4, 5, 6, 7, 8};
  double Loss() const {
    double l = std::abs(double(p[0]) - kink);
    for (size_t i = 0; i < p.size(); ++i) l += c[i] * double(p[i]) * p[i] / 2;
    return l;
  }
  std::vector<double> Gradient() const {
    std::vector<double> g(p.size());
    for (size_t i = 0; i < p.size(); ++i) g[i] = c[i] * p[i];
    g[0] -= 1;  // the kink's one-sided slope
    return g;
  }
};

TEST(GradientCheckTest, PassesTheRightGradientAndSkipsTheKink) {
  Quadratic q;
  ParameterGradientCheck check;
  check.top_k = 8;
  const auto report = check.Run(q.p.data(), q.Gradient(), [&] { return q.Loss(); });
  EXPECT_TRUE(report.ok()) << report.failures;
  EXPECT_EQ(report.checked, 7);  // p_0 sits on the kink
  EXPECT_EQ(q.p[1], -0.5f);      // parameters restored
}

// A kink 3e-6 from the parameter, a thousandth of the step: central differences at h and h/2 both
// average the two slopes and agree with each other, so only the one-sided slopes' parting shows it.
TEST(GradientCheckTest, SkipsAKinkRightBesideTheParameter) {
  Quadratic q;
  q.kink = 0.300003;
  ParameterGradientCheck check;
  check.top_k = 8;
  const auto report = check.Run(q.p.data(), q.Gradient(), [&] { return q.Loss(); });
  EXPECT_TRUE(report.ok()) << report.failures;
  EXPECT_EQ(report.checked, 7);
}

// Curvature parts the one-sided slopes too, but by half as much at half the step: a parameter a
// step's length from a steep minimum (h f'' = f') is still checked, and a wrong gradient there fails.
TEST(GradientCheckTest, ChecksAStronglyCurvedParameter) {
  float p = 0.3f;
  const auto loss = [&] { return 50.0 * (double(p) - 0.299) * (double(p) - 0.299); };
  const double right = 100.0 * (double(p) - 0.299);
  ParameterGradientCheck check;
  const auto report = check.Run(&p, std::vector<double>{right}, loss);
  EXPECT_TRUE(report.ok()) << report.failures;
  EXPECT_EQ(report.checked, 1);
  EXPECT_FALSE(check.Run(&p, std::vector<double>{1.1 * right}, loss).ok());
}

TEST(GradientCheckTest, FailsAWrongGradient) {
  Quadratic q;
  std::vector<double> g = q.Gradient();
  g[3] *= 1.1;  // 10 % off on one parameter
  ParameterGradientCheck check;
  check.top_k = 8;
  const auto report = check.Run(q.p.data(), g, [&] { return q.Loss(); });
  EXPECT_FALSE(report.ok());
  EXPECT_NE(report.failures.find("parameter 3"), std::string::npos) << report.failures;
  // All zero: nothing was tested, which is a failure too.
  const auto zero = check.Run(q.p.data(), std::vector<double>(8, 0.0), [] { return 0.0; });
  EXPECT_FALSE(zero.ok());
}

TEST(GradientCheckTest, FailsWhenKinksLeaveTooFewChecked) {
  Quadratic q;
  ParameterGradientCheck check;
  check.top_k = 8;
  check.min_checked = 8;
  EXPECT_FALSE(check.Run(q.p.data(), q.Gradient(), [&] { return q.Loss(); }).ok());
}

}  // namespace
}  // namespace icef::testing
