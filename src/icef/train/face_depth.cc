#include "icef/train/face_depth.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "icef/face/face_model.h"

namespace icef {

std::vector<float> FaceModelDepthTargets(const face::FaceFit& fit, const TrainingData& data,
                                         const std::vector<std::vector<float>>& expressions, const Executor& executor) {
  ICEF_CHECK(int(expressions.size()) == data.num_frames(), "depth targets: one expression per training frame");
  const face::FaceModel head(fit.shape, fit.style);
  std::vector<face::ExpressionState> states;
  for (const std::vector<float>& beta : expressions) {
    std::vector<float> clamped(face::kNumExpressions, 0.f);
    for (size_t i = 0; i < clamped.size() && i < beta.size(); ++i)
      clamped[i] = std::isfinite(beta[i]) ? std::max(beta[i], 0.f) : 0.f;
    states.push_back(head.Prepare(clamped));
  }
  const Aabb bounds = head.Bounds();
  const face::Similarity& s = fit.head_from_world;
  const Mat3f rotation = s.rotation.cast<float>();
  const float scale = static_cast<float>(s.scale);
  std::vector<float> depth(size_t(data.num_pixels()), std::numeric_limits<float>::quiet_NaN());
  const std::vector<int64_t>& pixels = data.region_pixels();
  ParallelFor(executor, int64_t(pixels.size()), [&](int64_t i0, int64_t i1, int) {
    for (int64_t i = i0; i < i1; ++i) {
      const int64_t p = pixels[i];
      const Ray world = data.PixelCentreRay(p);
      // x_head = scale R x + translation, so t along the world ray is t_head / scale along the
      // head-frame ray with the rotated (unit) direction.
      Ray ray;
      ray.origin = s.Apply(world.origin.cast<double>()).cast<float>();
      ray.direction = rotation * world.direction;
      const auto interval = bounds.Intersect(ray);
      if (!interval) continue;
      const float t = head.Trace(ray, interval->t_near, interval->t_far, states[data.frame_of_pixel(p)]);
      if (t >= 0.f) depth[p] = t / scale;
    }
  });
  return depth;
}

}  // namespace icef
