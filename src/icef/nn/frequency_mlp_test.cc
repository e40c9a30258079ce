#include "icef/nn/frequency_mlp.h"

#include <gtest/gtest.h>

#include "icef/nn/hash_grid.h"
#include "icef/testing/gradient_check.h"

namespace icef::nn {
namespace {

using testing::Dot;
using testing::MaxRelativeError;
using testing::RandomVector;

struct Composite {
  FrequencyEncodingOptions fo;
  std::vector<double> fw;
  MlpShape shape;
  int dc = 4;
  int64_t n = 5;
  std::vector<double> w, x, c, r;
  Composite() {
    fo.input_dims = 3;
    fo.num_frequencies = 3;
    FrequencyEncoding enc(fo);
    enc.SetAlpha(2.3);
    fw = enc.weights_double();
    shape = MlpShape({fo.output_dims() + dc, 16, 16, 3}, Activation::kNone);
    w = RandomVector(shape.num_params(), 8, 1, -0.5, 0.5);
    x = RandomVector(n * 3, 8, 2, -1, 1);
    c = RandomVector(n * dc, 8, 3, -1, 1);
    r = RandomVector(n * 3, 8, 4, -1, 1);
  }
  std::vector<double> Forward(std::vector<double>* in = nullptr,
                              std::vector<double>* hidden = nullptr) const {
    std::vector<double> i(n * shape.input_dims()), h(n * shape.hidden_per_sample()), y(n * 3);
    std::vector<double> scratch(FrequencyMlpScratch(shape, n));
    FrequencyMlpForward<double>(fo, fw.data(), shape, w.data(), n, x.data(), c.data(), i.data(), h.data(),
                                y.data(), scratch.data());
    if (in) *in = i;
    if (hidden) *hidden = h;
    return y;
  }
};

TEST(FrequencyMlpTest, GradientsMatchFiniteDifferences) {
  Composite m;
  std::vector<double> in, hidden;
  const std::vector<double> y = m.Forward(&in, &hidden);
  std::vector<double> wt(m.w.size()), dw(m.w.size(), 0.0), dx(m.x.size()), dc(m.c.size());
  std::vector<double> scratch(FrequencyMlpScratch(m.shape, m.n));
  MlpTransposeWeights<double>(m.shape, m.w.data(), wt.data());
  FrequencyMlpBackward<double>(m.fo, m.fw.data(), m.shape, wt.data(), m.n, m.x.data(), in.data(),
                               hidden.data(), y.data(), m.r.data(), dw.data(), dx.data(), dc.data(),
                               scratch.data());
  auto loss = [&] { return Dot(m.Forward(), m.r); };
  EXPECT_LT(MaxRelativeError(&m.w, dw, loss), 1e-6);
  EXPECT_LT(MaxRelativeError(&m.x, dx, loss), 1e-6);
  EXPECT_LT(MaxRelativeError(&m.c, dc, loss), 1e-6);
}

TEST(FrequencyMlpTest, JvpMatchesFiniteDifferencesOnEachSlice) {
  Composite m;
  const std::vector<double> vx = RandomVector(m.n * 3, 9, 1, -1, 1),
                            vc = RandomVector(m.n * m.dc, 9, 2, -1, 1);
  for (int mode = 0; mode < 3; ++mode) {  // x only, c only, both
    const bool use_x = mode != 1, use_c = mode != 0;
    std::vector<double> y(m.n * 3), jy(m.n * 3), scratch(FrequencyMlpScratch(m.shape, m.n));
    FrequencyMlpJvp<double>(m.fo, m.fw.data(), m.shape, m.w.data(), m.n, m.x.data(), m.c.data(),
                            use_x ? vx.data() : nullptr, use_c ? vc.data() : nullptr, y.data(), jy.data(),
                            scratch.data());
    const double h = 1e-6;
    Composite p = m, q = m;
    for (size_t i = 0; use_x && i < vx.size(); ++i) {
      p.x[i] += h * vx[i];
      q.x[i] -= h * vx[i];
    }
    for (size_t i = 0; use_c && i < vc.size(); ++i) {
      p.c[i] += h * vc[i];
      q.c[i] -= h * vc[i];
    }
    const std::vector<double> yp = p.Forward(), ym = q.Forward(), y0 = m.Forward();
    for (size_t i = 0; i < jy.size(); ++i) {
      EXPECT_NEAR(y[i], y0[i], 1e-12);
      const double fd = (yp[i] - ym[i]) / (2 * h);
      EXPECT_NEAR(jy[i], fd, 1e-6 * (std::abs(fd) + 1e-3)) << "mode " << mode << " output " << i;
    }
  }
}

TEST(FrequencyMlpTest, FloatModuleMatchesDoubleKernels) {
  FrequencyMlpOptions o;  // reference: 39 + 16 = 55 -> 64 -> 64 -> 64 -> 3
  ParameterStore store;
  FrequencyMlp net(o, &store, "deform");
  net.Initialize(3);
  net.encoding().SetAlpha(4.5);
  const int64_t n = 260;
  const std::vector<double> xd = RandomVector(n * 3, 4, 1, -1, 1), cd = RandomVector(n * 16, 4, 2, -1, 1);
  const std::vector<double> dyd = RandomVector(n * 3, 4, 3, -1, 1), vcd = RandomVector(n * 16, 4, 4, -1, 1);
  std::vector<float> x(xd.begin(), xd.end()), c(cd.begin(), cd.end()), dy(dyd.begin(), dyd.end()),
      vc(vcd.begin(), vcd.end());
  std::vector<float> y(n * 3), dx(n * 3), dc(n * 16), y2(n * 3), jy(n * 3);
  Executor ex(2);
  FrequencyMlpContext ctx;
  net.Forward(ex, n, x.data(), c.data(), y.data(), &ctx);
  net.Backward(ex, n, x.data(), y.data(), dy.data(), &ctx, dx.data(), dc.data());
  net.Jvp(ex, n, x.data(), c.data(), nullptr, vc.data(), y2.data(), jy.data(), &ctx);

  const MlpShape& s = net.mlp().shape();
  const std::vector<double> fw = net.encoding().weights_double();
  std::vector<double> w(net.mlp().weights(), net.mlp().weights() + s.num_params()), wt(w.size()),
      dw(w.size(), 0.0);
  std::vector<double> in(n * 55), h(n * s.hidden_per_sample()), yd(n * 3), dxd(n * 3), dcd(n * 16),
      jyd(n * 3), yj(n * 3);
  std::vector<double> scratch(FrequencyMlpScratch(s, n));
  FrequencyMlpForward<double>(o.encoding, fw.data(), s, w.data(), n, xd.data(), cd.data(), in.data(),
                              h.data(), yd.data(), scratch.data());
  MlpTransposeWeights<double>(s, w.data(), wt.data());
  FrequencyMlpBackward<double>(o.encoding, fw.data(), s, wt.data(), n, xd.data(), in.data(), h.data(),
                               yd.data(), dyd.data(), dw.data(), dxd.data(), dcd.data(), scratch.data());
  FrequencyMlpJvp<double>(o.encoding, fw.data(), s, w.data(), n, xd.data(), cd.data(), nullptr, vcd.data(),
                          yj.data(), jyd.data(), scratch.data());
  for (int64_t i = 0; i < n * 3; ++i) {
    ASSERT_NEAR(y[i], yd[i], 1e-4 * (1 + std::abs(yd[i])));
    ASSERT_NEAR(y2[i], yd[i], 1e-4 * (1 + std::abs(yd[i])));
    ASSERT_NEAR(jy[i], jyd[i], 1e-4 * (1 + std::abs(jyd[i])));
    ASSERT_NEAR(dx[i], dxd[i], 1e-3 * (1 + std::abs(dxd[i])));
  }
  for (int64_t i = 0; i < n * 16; ++i) ASSERT_NEAR(dc[i], dcd[i], 1e-4 * (1 + std::abs(dcd[i])));
  for (int64_t i = 0; i < s.num_params(); ++i) {
    ASSERT_NEAR(net.mlp().weight_grads()[i], dw[i], 1e-3 * (1 + std::abs(dw[i])));
  }
}

// Hash encoding followed by an MLP with an exp output: gradients w.r.t. the table, the MLP weights
// and the input positions through the composition.
TEST(ComposedTest, HashGridThenMlpGradientsMatchFiniteDifferences) {
  HashGridOptions go;
  go.num_levels = 3;
  go.features_per_level = 2;
  go.log2_table_size = 7;
  go.base_resolution = 3;
  go.finest_resolution = 11;
  const HashGridLayout g = MakeHashGridLayout(go);
  const MlpShape s({g.output_dims(), 16, 2}, Activation::kExp);
  const int64_t n = 6;
  std::vector<double> table = RandomVector(g.num_params(), 5, 1, -1, 1);
  std::vector<double> w = RandomVector(s.num_params(), 5, 2, -0.5, 0.5);
  std::vector<double> pos = RandomVector(n * 3, 5, 3, 0.01, 0.99);
  const std::vector<double> r = RandomVector(n * 2, 5, 4, -1, 1);
  auto loss = [&] {
    std::vector<double> f(n * g.output_dims()), h(n * s.hidden_per_sample()), y(n * 2);
    HashGridForward<double>(g, table.data(), n, pos.data(), f.data(), nullptr);
    MlpForward<double>(s, w.data(), n, f.data(), h.data(), y.data());
    return Dot(y, r);
  };
  std::vector<double> f(n * g.output_dims()), jac(f.size() * 3), h(n * s.hidden_per_sample()), y(n * 2);
  HashGridForward<double>(g, table.data(), n, pos.data(), f.data(), jac.data());
  MlpForward<double>(s, w.data(), n, f.data(), h.data(), y.data());
  std::vector<double> wt(w.size()), dw(w.size(), 0.0), df(f.size()), dtable(table.size(), 0.0), dpos(n * 3);
  std::vector<double> scratch(MlpBackwardScratch(s, n));
  MlpTransposeWeights<double>(s, w.data(), wt.data());
  MlpBackward<double>(s, wt.data(), n, f.data(), h.data(), y.data(), r.data(), dw.data(), df.data(),
                      scratch.data());
  HashGridBackwardParams<double>(g, n, pos.data(), df.data(), dtable.data(), 0, g.num_levels);
  HashGridBackwardInput<double>(g, n, jac.data(), df.data(), dpos.data());
  EXPECT_LT(MaxRelativeError(&w, dw, loss), 1e-6);
  EXPECT_LT(MaxRelativeError(&table, dtable, loss), 1e-6);
  EXPECT_LT(MaxRelativeError(&pos, dpos, loss), 1e-6);
}

}  // namespace
}  // namespace icef::nn
