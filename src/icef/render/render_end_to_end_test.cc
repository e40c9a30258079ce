// End-to-end gradient check of the renderer: a tiny analytic field (a Gaussian density blob with
// a sigmoid colour ramp, 9 parameters) rendered through SampleRays + CompositeForward (+ the
// distortion loss), with pixel-colour gradients w.r.t. the field parameters from the hand-written
// backward passes compared against central differences of the whole pipeline.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "icef/core/rng.h"
#include "icef/render/compositing.h"
#include "icef/render/distortion_loss.h"
#include "icef/render/ray_sampler.h"

namespace icef {
namespace {

// theta = [a, cx, cy, cz, s, b0, b1, b2, k]:
//   sigma(x) = a exp(-|x - c|^2 / (2 s^2)),  rgb_j(x) = sigmoid(b_j + k x_j)
constexpr int kNumParams = 9;

struct FieldEval {
  std::vector<double> sigma, rgb;
};

FieldEval EvalField(const std::vector<double>& theta, const std::vector<float>& positions) {
  const int64_t n = int64_t(positions.size() / 3);
  FieldEval f{std::vector<double>(n), std::vector<double>(3 * n)};
  for (int64_t i = 0; i < n; ++i) {
    double r2 = 0;
    for (int j = 0; j < 3; ++j) {
      const double d = positions[3 * i + j] - theta[1 + j];
      r2 += d * d;
    }
    f.sigma[i] = theta[0] * std::exp(-r2 / (2 * theta[4] * theta[4]));
    for (int j = 0; j < 3; ++j)
      f.rgb[3 * i + j] = 1 / (1 + std::exp(-(theta[5 + j] + theta[8] * positions[3 * i + j])));
  }
  return f;
}

struct Pipeline {
  RaySamples samples;
  std::vector<double> t, dt, bg;
  std::vector<double> g_color, g_opacity, g_depth;  // random loss weights per ray
  double distortion_weight = 0.05;
  CompositeOptions options;

  double Loss(const std::vector<double>& theta, std::vector<double>* grad) const {
    const FieldEval f = EvalField(theta, samples.positions);
    const CompositeInputs<double> in{f.sigma, f.rgb, t, dt, samples.ray_offset, samples.ray_count, bg};
    CompositeOutputs<double> out;
    const Executor executor(2);
    CompositeForward(in, options, executor, &out);
    std::vector<double> d_weights;
    double loss =
        distortion_weight * DistortionLoss<double>(out.weights, t, dt, samples.ray_offset, samples.ray_count,
                                                   distortion_weight, executor, grad ? &d_weights : nullptr);
    for (size_t r = 0; r < out.opacity.size(); ++r) {
      for (int k = 0; k < 3; ++k) loss += g_color[3 * r + k] * out.color[3 * r + k];
      loss += g_opacity[r] * out.opacity[r] + g_depth[r] * out.depth[r];
    }
    if (!grad) return loss;
    std::vector<double> d_sigma, d_rgb;
    CompositeBackward<double>(in, out, {g_color, g_opacity, g_depth, d_weights}, executor, &d_sigma, &d_rgb);
    // Chain rule through the analytic field.
    grad->assign(kNumParams, 0.0);
    for (int64_t i = 0; i < samples.size(); ++i) {
      const float* x = &samples.positions[3 * i];
      const double s = theta[4];
      double r2 = 0;
      for (int j = 0; j < 3; ++j) r2 += (x[j] - theta[1 + j]) * (x[j] - theta[1 + j]);
      const double e = std::exp(-r2 / (2 * s * s));
      (*grad)[0] += d_sigma[i] * e;
      for (int j = 0; j < 3; ++j)
        (*grad)[1 + j] += d_sigma[i] * theta[0] * e * (x[j] - theta[1 + j]) / (s * s);
      (*grad)[4] += d_sigma[i] * theta[0] * e * r2 / (s * s * s);
      for (int j = 0; j < 3; ++j) {
        const double c = f.rgb[3 * i + j];
        const double dz = d_rgb[3 * i + j] * c * (1 - c);
        (*grad)[5 + j] += dz;
        (*grad)[8] += dz * x[j];
      }
    }
    return loss;
  }
};

Pipeline MakePipeline(const RaySamplerOptions& sampler, uint64_t seed) {
  Pipeline p;
  std::vector<Ray> rays;
  Rng rng(seed, StreamId("e2e_rays"));
  for (int i = 0; i < 6; ++i) {
    const Vec3f target(rng.Uniform(-0.3, 0.3), rng.Uniform(-0.3, 0.3), 0.f);
    const Vec3f origin(0.2f * i - 0.5f, 0.1f, 3.f);
    rays.push_back(Ray{origin, (target - origin).normalized()});
  }
  SampleRays(rays, Aabb(), sampler, nullptr, seed, 0, Executor(2), &p.samples);
  p.t.assign(p.samples.t.begin(), p.samples.t.end());
  p.dt.assign(p.samples.dt.begin(), p.samples.dt.end());
  for (size_t r = 0; r < rays.size(); ++r) {
    for (int k = 0; k < 3; ++k) {
      p.bg.push_back(rng.Uniform(0.0, 1.0));  // per-ray background
      p.g_color.push_back(rng.Uniform(-1.0, 1.0));
    }
    p.g_opacity.push_back(rng.Uniform(-1.0, 1.0));
    p.g_depth.push_back(rng.Uniform(-0.3, 0.3));
  }
  return p;
}

void CheckPipeline(const Pipeline& p, const std::vector<double>& theta) {
  std::vector<double> grad;
  p.Loss(theta, &grad);
  for (int k = 0; k < kNumParams; ++k) {
    std::vector<double> a = theta, b = theta;
    const double h = 1e-6;
    a[k] += h;
    b[k] -= h;
    const double fd = (p.Loss(a, nullptr) - p.Loss(b, nullptr)) / (2 * h);
    EXPECT_NEAR(grad[k], fd, 1e-7 * (1 + std::abs(fd))) << "parameter " << k;
  }
}

TEST(RenderEndToEndTest, FixedCountGradientWrtFieldParameters) {
  RaySamplerOptions sampler;
  sampler.num_samples = 48;
  const Pipeline p = MakePipeline(sampler, 3);
  CheckPipeline(p, {6.0, 0.05, -0.1, 0.1, 0.35, 0.2, -0.3, 0.1, 1.5});
}

TEST(RenderEndToEndTest, MarchingDenseBlobWithEarlyTerminationGradient) {
  RaySamplerOptions sampler;
  sampler.step_size = 0.02f;
  sampler.cone_angle = 0.004f;
  Pipeline p = MakePipeline(sampler, 5);
  p.options.transmittance_eps = 1e-3;
  CheckPipeline(p, {40.0, 0.0, 0.0, 0.0, 0.3, -0.2, 0.4, 0.0, -1.0});
}

}  // namespace
}  // namespace icef
