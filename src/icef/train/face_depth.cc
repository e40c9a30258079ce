#include "icef/train/face_depth.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "icef/data/landmark_region.h"
#include "icef/face/face_model.h"

namespace icef {

std::vector<float> FaceModelDepthTargets(const face::FaceFit& fit, const TrainingData& data,
                                         const std::vector<std::vector<float>>& expressions,
                                         const std::vector<int64_t>& pixels, const Executor& executor) {
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

std::vector<int64_t> EyePixels(const Dataset& dataset, const TrainingData& data) {
  std::vector<int64_t> pixels;
  for (int k = 0; k < data.num_frames() && k < int(dataset.train.size()); ++k) {
    if (!dataset.train[k].landmarks_2d) continue;
    const std::vector<Vec2f>& all = *dataset.train[k].landmarks_2d;
    const int width = data.camera(k).width(), height = data.camera(k).height();
    std::vector<uint8_t> eye(size_t(width) * height, 0);
    for (int first : {36, 42}) {
      // ExpressionRegion skips non-finite landmarks: keep this eye's six.
      std::vector<Vec2f> one(all.size(), Vec2f::Constant(std::numeric_limits<float>::quiet_NaN()));
      for (int i = first; i < first + 6 && i < int(all.size()); ++i) one[i] = all[i];
      const Image region = ExpressionRegion(width, height, one, {}, DefaultRegionDilation(width));
      for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
          if (region.At(x, y, 0) > 0.f) eye[size_t(y) * width + x] = 1;
    }
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        if (eye[size_t(y) * width + x]) pixels.push_back(data.PixelIndex(k, x, y));
  }
  return pixels;
}

}  // namespace icef
