// Test helpers for the model module: a face-like set of 68 iBUG landmarks and tiny configs.
#pragma once

#include <vector>

#include "icef/core/rng.h"
#include "icef/model/avatar_model.h"

namespace icef::testing_model {

// 68 landmarks of a frontal face of height ~0.6 centred at the origin, looking along +z.
inline std::vector<Vec3f> FaceLandmarks() {
  std::vector<Vec3f> p(68);
  for (int i = 0; i <= 16; ++i) {  // jaw: an arc from ear to ear
    const float a = float(M_PI) * (0.1f + 0.8f * i / 16.f);
    p[i] = Vec3f(-0.3f * std::cos(a), -0.3f * std::sin(a) + 0.05f, 0.1f);
  }
  for (int i = 0; i < 5; ++i) p[17 + i] = Vec3f(-0.22f + 0.04f * i, 0.17f + 0.01f * (i % 2), 0.25f);  // brows
  for (int i = 0; i < 5; ++i) p[22 + i] = Vec3f(0.06f + 0.04f * i, 0.17f + 0.01f * (i % 2), 0.25f);
  for (int i = 0; i < 9; ++i)
    p[27 + i] = Vec3f(0.f + 0.01f * (i - 4) * (i > 3), 0.1f - 0.04f * std::min(i, 4), 0.3f);
  for (int e = 0; e < 2; ++e)  // eyes: 6-point loops
    for (int i = 0; i < 6; ++i) {
      const float a = float(M_PI) * i / 3.f;
      p[36 + 6 * e + i] =
          Vec3f((e ? 0.11f : -0.11f) - 0.04f * std::cos(a), 0.1f + 0.015f * std::sin(a), 0.24f);
    }
  for (int i = 0; i < 12; ++i) {  // outer lip loop
    const float a = float(M_PI) * i / 6.f;
    p[48 + i] = Vec3f(-0.08f * std::cos(a), -0.17f + 0.03f * std::sin(a), 0.26f);
  }
  for (int i = 0; i < 8; ++i) {  // inner lip loop
    const float a = float(M_PI) * i / 4.f;
    p[60 + i] = Vec3f(-0.06f * std::cos(a), -0.17f + 0.01f * std::sin(a), 0.26f);
  }
  return p;
}

// A small, fast model configuration for tests.
inline ModelConfig TinyModelConfig(const std::string& method) {
  ModelConfig c;
  c.method = method;
  c.static_field.grid.num_levels = 4;
  c.static_field.grid.log2_table_size = 10;
  c.static_field.grid.base_resolution = 4;
  c.static_field.grid.finest_resolution = 32;
  c.static_field.density_hidden = 16;
  c.static_field.geo_features = 8;
  c.static_field.color_hidden = {16};
  c.deformation.hidden = {16, 16};
  c.deformation.num_frequencies = 3;
  c.sampler.num_samples = 16;
  c.occupancy.resolution = 16;
  return c;
}

inline ModelSetup TinySetup(int expression_dim = 3) {
  ModelSetup s;
  s.aabb = Aabb{Vec3f(-0.5f, -0.5f, -0.5f), Vec3f(0.5f, 0.5f, 0.5f)};
  s.expression_dim = expression_dim;
  for (int k = 0; k < 3; ++k) {
    std::vector<float> e(expression_dim, 0.f);
    e[k % expression_dim] = 0.5f;
    s.training_expressions.push_back(e);
  }
  s.mask_landmarks = FaceLandmarks();
  s.mask_source = "test";
  for (int k = 0; k < 3; ++k) {
    Intrinsics in;
    in.width = in.height = 16;
    in.fl_x = in.fl_y = 20;
    in.cx = in.cy = 8;
    s.training_cameras.push_back(Camera::LookAt(in, Vec3d(0.5 * (k - 1), 0, 2), Vec3d::Zero()));
  }
  return s;
}

// `rays` training rays along -z through random points of [-0.2, 0.2] x [y_lo, 0.2], frames
// cycling over the 3 training frames, random targets (and alpha targets when `alpha`).
inline TrainRays RandomBatch(int rays, uint64_t seed, bool alpha = true, double y_lo = -0.2) {
  TrainRays batch;
  Rng rng(seed, StreamId("batch"));
  for (int r = 0; r < rays; ++r) {
    const Vec3f o(static_cast<float>(rng.Uniform(-0.2, 0.2)), static_cast<float>(rng.Uniform(y_lo, 0.2)),
                  2.f);
    batch.rays.push_back(Ray{o, Vec3f(0, 0, -1)});
    batch.frame.push_back(r % 3);
    for (int a = 0; a < 3; ++a) batch.target_rgb.push_back(static_cast<float>(rng.Uniform()));
    if (alpha) batch.target_alpha.push_back(static_cast<float>(rng.Uniform()));
  }
  return batch;
}

}  // namespace icef::testing_model
