#include "icef/render/compositing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "icef/core/rng.h"

namespace icef {
namespace {

struct RayData {
  int n;
  std::vector<double> sigma, rgb, t, dt, bg;
};

RayData RandomRay(int n, uint64_t seed, double sigma_scale) {
  Rng rng(seed, StreamId("composite_test"));
  RayData r{n, {}, {}, {}, {}, {}};
  double t = 0.5;
  for (int i = 0; i < n; ++i) {
    const double dt = rng.Uniform(0.02, 0.1);
    r.dt.push_back(dt);
    r.t.push_back(t + 0.5 * dt);
    t += dt;
    r.sigma.push_back(sigma_scale * rng.Uniform(0.0, 1.0));
    for (int k = 0; k < 3; ++k) r.rgb.push_back(rng.Uniform(0.0, 1.0));
  }
  for (int k = 0; k < 3; ++k) r.bg.push_back(rng.Uniform(0.0, 1.0));
  return r;
}

// Scalar loss used by the gradient checks: random linear functional of all outputs, plus an
// optional linear functional of the weights.
struct LossWeights {
  double dc[3], dop, dd;
  std::vector<double> dw;
};

double Loss(const RayData& r, double eps, const LossWeights& g, int* used = nullptr) {
  double c[3], op, d;
  std::vector<double> w(r.n);
  const int m = CompositeRayForward<double>(r.n, r.sigma.data(), r.rgb.data(), r.t.data(), r.dt.data(),
                                            r.bg.data(), eps, c, &op, &d, w.data());
  if (used) *used = m;
  double loss = g.dc[0] * c[0] + g.dc[1] * c[1] + g.dc[2] * c[2] + g.dop * op + g.dd * d;
  for (int i = 0; i < r.n && !g.dw.empty(); ++i) loss += g.dw[i] * w[i];
  return loss;
}

TEST(CompositingTest, MatchesNaiveReference) {
  const RayData r = RandomRay(20, 1, 10.0);
  double c[3], op, d;
  std::vector<double> w(r.n);
  CompositeRayForward<double>(r.n, r.sigma.data(), r.rgb.data(), r.t.data(), r.dt.data(), r.bg.data(), 0.0, c,
                              &op, &d, w.data());
  double ref_c[3] = {0, 0, 0}, ref_d = 0, sum_w = 0;
  for (int i = 0; i < r.n; ++i) {
    double trans = 1;
    for (int j = 0; j < i; ++j) trans *= std::exp(-r.sigma[j] * r.dt[j]);
    const double wi = trans * (1 - std::exp(-r.sigma[i] * r.dt[i]));
    EXPECT_NEAR(w[i], wi, 1e-14);
    for (int k = 0; k < 3; ++k) ref_c[k] += wi * r.rgb[3 * i + k];
    ref_d += wi * r.t[i];
    sum_w += wi;
  }
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], ref_c[k] + (1 - sum_w) * r.bg[k], 1e-13);
  EXPECT_NEAR(op, sum_w, 1e-13);
  EXPECT_NEAR(d, ref_d, 1e-13);
}

void CheckGradient(const RayData& base, double eps, bool with_dw, uint64_t seed) {
  Rng rng(seed, StreamId("composite_grad"));
  LossWeights g;
  for (double& v : g.dc) v = rng.Uniform(-1, 1);
  g.dop = rng.Uniform(-1, 1);
  g.dd = rng.Uniform(-1, 1);
  if (with_dw)
    for (int i = 0; i < base.n; ++i) g.dw.push_back(rng.Uniform(-1, 1));
  int m = 0;
  Loss(base, eps, g, &m);
  std::vector<double> d_sigma(base.n), d_rgb(3 * base.n);
  CompositeRayBackward<double>(base.n, m, base.sigma.data(), base.rgb.data(), base.t.data(), base.dt.data(),
                               base.bg.data(), g.dc, g.dop, g.dd, with_dw ? g.dw.data() : nullptr,
                               d_sigma.data(), d_rgb.data());
  const double h = 1e-6;
  for (int i = 0; i < base.n; ++i) {
    RayData p = base, q = base;
    p.sigma[i] += h;
    q.sigma[i] -= h;
    const double fd = (Loss(p, eps, g) - Loss(q, eps, g)) / (2 * h);
    EXPECT_NEAR(d_sigma[i], fd, 1e-8 * (1 + std::abs(fd))) << "sigma " << i;
    for (int k = 0; k < 3; ++k) {
      RayData a = base, b = base;
      a.rgb[3 * i + k] += h;
      b.rgb[3 * i + k] -= h;
      const double fd_rgb = (Loss(a, eps, g) - Loss(b, eps, g)) / (2 * h);
      EXPECT_NEAR(d_rgb[3 * i + k], fd_rgb, 1e-8 * (1 + std::abs(fd_rgb))) << "rgb " << i << "," << k;
    }
  }
}

TEST(CompositingTest, GradientMatchesCentralDifferences) {
  for (uint64_t seed = 0; seed < 5; ++seed) CheckGradient(RandomRay(16, 10 + seed, 8.0), 0.0, false, seed);
}

TEST(CompositingTest, GradientWithWeightGradientsMatchesCentralDifferences) {
  for (uint64_t seed = 0; seed < 5; ++seed) CheckGradient(RandomRay(12, 20 + seed, 8.0), 0.0, true, seed);
}

TEST(CompositingTest, EarlyTerminationStopsAndItsBackwardIsConsistent) {
  const RayData r = RandomRay(40, 3, 60.0);  // dense: transmittance falls fast
  LossWeights g{{0.3, -0.2, 0.5}, 0.7, -0.1, {}};
  int m_full = 0, m_term = 0;
  Loss(r, 0.0, g, &m_full);
  const double eps = 1e-3;
  const double loss_term = Loss(r, eps, g, &m_term);
  EXPECT_EQ(m_full, 40);
  ASSERT_LT(m_term, 40);
  ASSERT_GT(m_term, 1);
  // Termination changes the outputs by at most about eps.
  EXPECT_NEAR(loss_term, Loss(r, 0.0, g), 3 * eps);
  // Samples past the termination point get zero gradient; the others match central differences.
  CheckGradient(r, eps, true, 4);
  std::vector<double> d_sigma(r.n), d_rgb(3 * r.n);
  CompositeRayBackward<double>(r.n, m_term, r.sigma.data(), r.rgb.data(), r.t.data(), r.dt.data(),
                               r.bg.data(), g.dc, g.dop, g.dd, nullptr, d_sigma.data(), d_rgb.data());
  for (int i = m_term; i < r.n; ++i) EXPECT_EQ(d_sigma[i], 0.0);
}

// CompositeRayUsed counts, from the densities alone, exactly the samples the float forward uses,
// on rays that end early at every training and render threshold and on rays that never do.
TEST(CompositingTest, UsedSamplesAreThoseTheForwardUses) {
  int terminated = 0;
  for (uint64_t seed = 0; seed < 400; ++seed) {
    const RayData r = RandomRay(1 + int(seed % 97), 100 + seed, 0.5 * double(seed % 40));
    const std::vector<float> sigma(r.sigma.begin(), r.sigma.end()), dt(r.dt.begin(), r.dt.end()),
        rgb(r.rgb.begin(), r.rgb.end()), t(r.t.begin(), r.t.end()), bg(r.bg.begin(), r.bg.end());
    for (const float eps : {0.f, 1e-4f, 1e-2f, 0.3f}) {
      float c[3], op, d;
      const int m = CompositeRayForward<float>(r.n, sigma.data(), rgb.data(), t.data(), dt.data(), bg.data(),
                                               eps, c, &op, &d, nullptr);
      ASSERT_EQ(CompositeRayUsed<float>(r.n, sigma.data(), dt.data(), eps), m) << seed << " " << eps;
      terminated += m < r.n;
    }
  }
  EXPECT_GT(terminated, 400);  // most rays with a threshold end early
}

TEST(CompositingTest, BatchedMatchesPerRayAndFloatMatchesDouble) {
  std::vector<RayData> rays = {RandomRay(7, 1, 5.0), RandomRay(0, 2, 5.0), RandomRay(11, 3, 5.0)};
  std::vector<double> sigma, rgb, t, dt, bg;
  std::vector<int32_t> offset, count;
  for (const RayData& r : rays) {
    offset.push_back(int32_t(sigma.size()));
    count.push_back(r.n);
    sigma.insert(sigma.end(), r.sigma.begin(), r.sigma.end());
    rgb.insert(rgb.end(), r.rgb.begin(), r.rgb.end());
    t.insert(t.end(), r.t.begin(), r.t.end());
    dt.insert(dt.end(), r.dt.begin(), r.dt.end());
    bg.insert(bg.end(), r.bg.begin(), r.bg.end());
  }
  CompositeInputs<double> in{sigma, rgb, t, dt, offset, count, bg};
  CompositeOutputs<double> out;
  CompositeOptions options;
  options.transmittance_eps = 0;
  CompositeForward(in, options, Executor(2), &out);
  for (size_t r = 0; r < rays.size(); ++r) {
    double c[3], op, d;
    CompositeRayForward<double>(rays[r].n, rays[r].sigma.data(), rays[r].rgb.data(), rays[r].t.data(),
                                rays[r].dt.data(), rays[r].bg.data(), 0.0, c, &op, &d, nullptr);
    for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(out.color[3 * r + k], c[k]);
    EXPECT_DOUBLE_EQ(out.opacity[r], op);
  }
  EXPECT_DOUBLE_EQ(out.color[3], rays[1].bg[0]);  // the empty ray shows its background
  // Backward, batched, against the per-ray kernel.
  std::vector<double> d_color(9, 0.5), d_sigma, d_rgb;
  CompositeBackward<double>(in, out, {d_color, {}, {}, {}}, Executor(2), &d_sigma, &d_rgb);
  ASSERT_EQ(d_sigma.size(), sigma.size());
  std::vector<double> ref_sigma(11), ref_rgb(33);
  CompositeRayBackward<double>(11, out.num_used[2], rays[2].sigma.data(), rays[2].rgb.data(),
                               rays[2].t.data(), rays[2].dt.data(), rays[2].bg.data(), d_color.data(), 0.0,
                               0.0, nullptr, ref_sigma.data(), ref_rgb.data());
  for (int i = 0; i < 11; ++i) EXPECT_DOUBLE_EQ(d_sigma[7 + i], ref_sigma[i]);
  // Float path agrees with double to float precision.
  std::vector<float> fs(sigma.begin(), sigma.end()), frgb(rgb.begin(), rgb.end()), ft(t.begin(), t.end()),
      fdt(dt.begin(), dt.end()), fbg(bg.begin(), bg.end());
  CompositeOutputs<float> fout;
  CompositeForward(CompositeInputs<float>{fs, frgb, ft, fdt, offset, count, fbg}, options, Executor(1),
                   &fout);
  for (size_t k = 0; k < out.color.size(); ++k) EXPECT_NEAR(fout.color[k], out.color[k], 1e-5);
}

TEST(CompositingTest, OpaqueSurfaceGivesItsColourAndDepth) {
  // One very dense sample: colour = its rgb, opacity = 1, depth = its t.
  const double sigma[2] = {1e4, 1.0}, rgb[6] = {0.2, 0.4, 0.6, 1, 1, 1}, t[2] = {1.5, 1.7},
               dt[2] = {0.1, 0.1}, bg[3] = {1, 1, 1};
  double c[3], op, d;
  const int m = CompositeRayForward<double>(2, sigma, rgb, t, dt, bg, 1e-4, c, &op, &d, nullptr);
  EXPECT_EQ(m, 1);
  EXPECT_NEAR(c[0], 0.2, 1e-9);
  EXPECT_NEAR(c[2], 0.6, 1e-9);
  EXPECT_NEAR(op, 1.0, 1e-9);
  EXPECT_NEAR(d, 1.5, 1e-9);
}

}  // namespace
}  // namespace icef
