#include "icef/train/face_depth.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "icef/core/rng.h"
#include "icef/data/landmark_region.h"
#include "icef/face/face_model.h"

namespace icef {

namespace {

// The fitted face model, its state at each training frame's expression, and world-ray tracing.
struct FittedHead {
  FittedHead(const face::FaceFit& fit, const std::vector<std::vector<float>>& expressions)
      : head(fit.shape, fit.style), bounds(head.Bounds()), s(fit.head_from_world) {
    for (const std::vector<float>& beta : expressions) {
      std::vector<float> clamped(face::kNumExpressions, 0.f);
      for (size_t i = 0; i < clamped.size() && i < beta.size(); ++i)
        clamped[i] = std::isfinite(beta[i]) ? std::max(beta[i], 0.f) : 0.f;
      states.push_back(head.Prepare(clamped));
    }
  }
  // The world ray parameter where `world` meets the surface at frame k's expression, or NaN.
  float Depth(const Ray& world, int k) const {
    // x_head = scale R x + translation, so t along the world ray is t_head / scale along the
    // head-frame ray with the rotated (unit) direction.
    Ray ray;
    ray.origin = s.Apply(world.origin.cast<double>()).cast<float>();
    ray.direction = s.rotation.cast<float>() * world.direction;
    const auto interval = bounds.Intersect(ray);
    if (!interval) return std::numeric_limits<float>::quiet_NaN();
    const float t = head.Trace(ray, interval->t_near, interval->t_far, states[k]);
    return t >= 0.f ? t / static_cast<float>(s.scale) : std::numeric_limits<float>::quiet_NaN();
  }

  face::FaceModel head;
  Aabb bounds;
  face::Similarity s;
  std::vector<face::ExpressionState> states;
};

}  // namespace

ViewRayOptions::Region ViewRegionFromName(const std::string& name) {
  if (name == "upper") return ViewRayOptions::Region::kUpper;
  if (name == "face") return ViewRayOptions::Region::kFace;
  ICEF_CHECK(name == "expression", "unknown unseen-view region " + name);
  return ViewRayOptions::Region::kExpression;
}

std::vector<float> FaceModelDepthTargets(const face::FaceFit& fit, const TrainingData& data,
                                         const std::vector<std::vector<float>>& expressions,
                                         const std::vector<int64_t>& pixels, const Executor& executor) {
  ICEF_CHECK(int(expressions.size()) == data.num_frames(),
             "depth targets: one expression per training frame");
  const FittedHead fitted(fit, expressions);
  std::vector<float> depth(size_t(data.num_pixels()), std::numeric_limits<float>::quiet_NaN());
  ParallelFor(executor, int64_t(pixels.size()), [&](int64_t i0, int64_t i1, int) {
    for (int64_t i = i0; i < i1; ++i) {
      const int64_t p = pixels[i];
      depth[p] = fitted.Depth(data.PixelCentreRay(p), data.frame_of_pixel(p));
    }
  });
  return depth;
}

std::vector<std::vector<Camera>> UnseenViewCameras(const face::FaceFit& fit, const TrainingData& data,
                                                   const ViewRayOptions& options) {
  const face::FaceModel head(fit.shape, fit.style);
  Vec3d centre_head = Vec3d::Zero();
  for (const Vec3f& p : head.NeutralLandmarks()) centre_head += p.cast<double>();
  centre_head /= double(head.NeutralLandmarks().size());
  const Vec3d pivot = fit.head_from_world.ApplyInverse(centre_head);
  const Vec3d up = (fit.head_from_world.rotation.transpose() * Vec3d::UnitY()).normalized();
  constexpr double kDegree = 3.14159265358979323846 / 180.0;
  std::vector<std::vector<Camera>> cameras(size_t(data.num_frames()));
  for (int k = 0; k < data.num_frames(); ++k) {
    const Camera& camera = data.camera(k);
    Rng rng(options.seed, StreamId("depth_prior_views"), uint64_t(k));
    for (int v = 0; v < options.views_per_frame; ++v) {
      const double yaw = rng.Uniform(-options.max_yaw_deg, options.max_yaw_deg) * kDegree;
      const double pitch = rng.Uniform(-options.max_pitch_deg, options.max_pitch_deg) * kDegree;
      const Vec3d right = camera.world_from_cam().block<3, 1>(0, 0).normalized();
      const Mat3d turn = (Eigen::AngleAxisd(yaw, up) * Eigen::AngleAxisd(pitch, right)).toRotationMatrix();
      Mat4d world_from_cam = camera.world_from_cam();
      world_from_cam.block<3, 3>(0, 0) = turn * world_from_cam.block<3, 3>(0, 0);
      world_from_cam.block<3, 1>(0, 3) = pivot + turn * (camera.Center() - pivot);
      cameras[k].emplace_back(camera.intrinsics(), world_from_cam);
    }
  }
  return cameras;
}

std::vector<ViewRay> FaceModelViewRays(const face::FaceFit& fit, const TrainingData& data,
                                       const std::vector<std::vector<float>>& expressions,
                                       const ViewRayOptions& options, const Executor& executor) {
  ICEF_CHECK(int(expressions.size()) == data.num_frames(), "view rays: one expression per training frame");
  const FittedHead fitted(fit, expressions);
  const std::vector<std::vector<Camera>> cameras = UnseenViewCameras(fit, data, options);
  std::vector<ViewRay> out;
  for (int k = 0; k < data.num_frames(); ++k) {
    const std::array<Vec3f, 68> landmarks = fitted.head.Landmarks(fitted.states[k]);
    for (const Camera& camera : cameras[k]) {
      std::vector<Vec2f> projected(landmarks.size(),
                                   Vec2f::Constant(std::numeric_limits<float>::quiet_NaN()));
      for (size_t i = 0; i < landmarks.size(); ++i)
        if (const auto p = camera.Project(fitted.s.ApplyInverse(landmarks[i].cast<double>())))
          projected[i] = p->uv.cast<float>();
      if (options.region == ViewRayOptions::Region::kUpper)  // drop the mouth (iBUG 48-67)
        for (size_t i = 48; i < projected.size(); ++i)
          projected[i] = Vec2f::Constant(std::numeric_limits<float>::quiet_NaN());
      const int width = camera.width(), height = camera.height();
      const Image region = ExpressionRegion(width, height, projected, {}, DefaultRegionDilation(width));
      const Image hull = options.region == ViewRayOptions::Region::kFace
                             ? LandmarkHullRegion(width, height, projected)
                             : Image(width, height, 1, 0.f);
      std::vector<int64_t> pixels;
      for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
          if (region.At(x, y, 0) > 0.f || hull.At(x, y, 0) > 0.f) pixels.push_back(int64_t(y) * width + x);
      std::vector<ViewRay> rays(pixels.size());
      ParallelFor(executor, int64_t(pixels.size()), [&](int64_t i0, int64_t i1, int) {
        for (int64_t i = i0; i < i1; ++i) {
          const Ray ray = camera.PixelRay(int(pixels[i] % width), int(pixels[i] / width));
          rays[i] = ViewRay{ray, int32_t(k), fitted.Depth(ray, k)};
        }
      });
      for (const ViewRay& r : rays)
        if (std::isfinite(r.depth)) out.push_back(r);
    }
  }
  return out;
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

std::vector<int64_t> FacePixels(const Dataset& dataset, const TrainingData& data) {
  std::vector<uint8_t> face(size_t(data.num_pixels()), 0);
  for (int64_t p : data.region_pixels()) face[size_t(p)] = 1;
  for (int k = 0; k < data.num_frames() && k < int(dataset.train.size()); ++k) {
    if (!dataset.train[k].landmarks_2d) continue;
    const int width = data.camera(k).width(), height = data.camera(k).height();
    const Image hull = LandmarkHullRegion(width, height, *dataset.train[k].landmarks_2d);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        if (hull.At(x, y, 0) > 0.f) face[size_t(data.PixelIndex(k, x, y))] = 1;
  }
  std::vector<int64_t> pixels;
  for (size_t p = 0; p < face.size(); ++p)
    if (face[p]) pixels.push_back(int64_t(p));
  return pixels;
}

}  // namespace icef
