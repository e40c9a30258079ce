#include "icef/train/face_depth.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "icef/core/rng.h"
#include "icef/data/landmark_region.h"
#include "icef/face/face_model.h"
#include "icef/face/ict_warp.h"
#include "icef/face/mesh_depth.h"

namespace icef {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Negative and non-finite weights act as 0.
std::vector<float> Clamped(const std::vector<float>& beta, size_t size) {
  std::vector<float> out(size, 0.f);
  for (size_t i = 0; i < size && i < beta.size(); ++i)
    out[i] = std::isfinite(beta[i]) ? std::max(beta[i], 0.f) : 0.f;
  return out;
}

// The procedural face model: sphere-traced along each ray.
class ProceduralSurface final : public FittedSurface {
 public:
  ProceduralSurface(const face::FaceFit& fit, const std::vector<std::vector<float>>& expressions)
      : head_(fit.shape, fit.style), bounds_(head_.Bounds()), s_(fit.head_from_world) {
    for (const std::vector<float>& beta : expressions)
      states_.push_back(head_.Prepare(Clamped(beta, face::kNumExpressions)));
    Vec3d centre_head = Vec3d::Zero();
    for (const Vec3f& p : head_.NeutralLandmarks()) centre_head += p.cast<double>();
    centre_head /= double(head_.NeutralLandmarks().size());
    pivot = s_.ApplyInverse(centre_head);
    up = (s_.rotation.transpose() * Vec3d::UnitY()).normalized();
  }

  std::vector<float> Depths(const Camera& camera, int k, std::span<const int64_t> pixels,
                            const Executor& executor) const override {
    std::vector<float> out(pixels.size());
    ParallelFor(executor, int64_t(pixels.size()), [&](int64_t i0, int64_t i1, int) {
      for (int64_t i = i0; i < i1; ++i)
        out[i] = Depth(camera.PixelRay(int(pixels[i] % camera.width()), int(pixels[i] / camera.width())), k);
    });
    return out;
  }

  std::array<Vec3f, 68> Landmarks(int k) const override {
    std::array<Vec3f, 68> out = head_.Landmarks(states_[k]);
    for (Vec3f& p : out) p = s_.ApplyInverse(p.cast<double>()).cast<float>();
    return out;
  }

 private:
  // The world ray parameter where `world` meets the surface at frame k's expression, or NaN.
  float Depth(const Ray& world, int k) const {
    // x_head = scale R x + translation, so t along the world ray is t_head / scale along the
    // head-frame ray with the rotated (unit) direction.
    Ray ray;
    ray.origin = s_.Apply(world.origin.cast<double>()).cast<float>();
    ray.direction = s_.rotation.cast<float>() * world.direction;
    const auto interval = bounds_.Intersect(ray);
    if (!interval) return kNaN;
    const float t = head_.Trace(ray, interval->t_near, interval->t_far, states_[k]);
    return t >= 0.f ? t / static_cast<float>(s_.scale) : kNaN;
  }

  face::FaceModel head_;
  Aabb bounds_;
  face::Similarity s_;
  std::vector<face::ExpressionState> states_;
};

// ICT-FaceKit: the posed meshes (the warp's surfaces: skin, mouth interior, teeth, eyes) in the
// world frame, each camera's pixels intersected exactly (face/mesh_depth.h).
class IctSurface final : public FittedSurface {
 public:
  static Result<std::unique_ptr<FittedSurface>> Create(const IctFaceFit& fit,
                                                       const std::vector<std::vector<float>>& expressions) {
    ICEF_ASSIGN_OR_RETURN(const std::shared_ptr<const face::IctModel> model, face::IctModel::LoadDefault());
    ICEF_ASSIGN_OR_RETURN(const face::IctWarp warp, face::IctWarp::Create(*model, fit.identity));
    std::unique_ptr<IctSurface> s(new IctSurface);
    s->triangles_ = warp.triangles();
    const auto to_world = [&](const std::vector<Vec3f>& head) {
      std::vector<Vec3f> world;
      for (const Vec3f& p : head)
        world.push_back(fit.head_from_world.ApplyInverse(p.cast<double>()).cast<float>());
      return world;
    };
    for (const std::vector<float>& beta : expressions)
      s->meshes_.push_back(to_world(model->Mesh(fit.identity, Clamped(beta, model->num_expressions()))));
    for (const std::vector<Vec3f>& mesh : s->meshes_) {
      const std::vector<Vec3f> lm = model->Landmarks(mesh);
      std::array<Vec3f, 68> a;
      std::copy(lm.begin(), lm.end(), a.begin());
      s->landmarks_.push_back(a);
    }
    Vec3d centre = Vec3d::Zero();
    for (const Vec3f& p : to_world(model->Landmarks(warp.neutral()))) centre += p.cast<double>();
    s->pivot = centre / 68.0;
    s->up = (fit.head_from_world.rotation.transpose() * Vec3d::UnitY()).normalized();
    return std::unique_ptr<FittedSurface>(std::move(s));
  }

  std::vector<float> Depths(const Camera& camera, int k, std::span<const int64_t> pixels,
                            const Executor&) const override {
    const std::vector<float> image = face::MeshDepthImage(meshes_[k], triangles_, camera);
    std::vector<float> out;
    for (const int64_t p : pixels) out.push_back(std::isfinite(image[size_t(p)]) ? image[size_t(p)] : kNaN);
    return out;
  }

  std::array<Vec3f, 68> Landmarks(int k) const override { return landmarks_[k]; }

 private:
  IctSurface() = default;
  std::vector<std::array<uint32_t, 3>> triangles_;
  std::vector<std::vector<Vec3f>> meshes_;  // per training frame, world frame
  std::vector<std::array<Vec3f, 68>> landmarks_;
};

}  // namespace

FittedSurface::~FittedSurface() = default;

Result<std::unique_ptr<FittedSurface>> FittedSurface::Create(
    const ModelSetup& setup, const std::vector<std::vector<float>>& expressions) {
  if (setup.ict_fit) return IctSurface::Create(*setup.ict_fit, expressions);
  if (setup.face_fit)
    return std::unique_ptr<FittedSurface>(std::make_unique<ProceduralSurface>(*setup.face_fit, expressions));
  return Status::Error("the face model's depth: the model setup has no face-model fit");
}

ViewRayOptions::Region ViewRegionFromName(const std::string& name) {
  if (name == "upper") return ViewRayOptions::Region::kUpper;
  if (name == "face") return ViewRayOptions::Region::kFace;
  ICEF_CHECK(name == "expression", "unknown unseen-view region " + name);
  return ViewRayOptions::Region::kExpression;
}

std::vector<float> FaceModelDepthTargets(const FittedSurface& surface, const TrainingData& data,
                                         const std::vector<int64_t>& pixels, const Executor& executor) {
  std::vector<float> depth(size_t(data.num_pixels()), kNaN);
  // The pixels frame by frame (as each frame's own pixel indices).
  std::vector<std::vector<int64_t>> global(size_t(data.num_frames())), local(size_t(data.num_frames()));
  for (const int64_t p : pixels) {
    const int k = data.frame_of_pixel(p);
    global[k].push_back(p);
    local[k].push_back(p - data.PixelIndex(k, 0, 0));
  }
  for (int k = 0; k < data.num_frames(); ++k) {
    if (local[k].empty()) continue;
    const std::vector<float> d = surface.Depths(data.camera(k), k, local[k], executor);
    for (size_t i = 0; i < d.size(); ++i) depth[size_t(global[k][i])] = d[i];
  }
  return depth;
}

std::vector<std::vector<Camera>> UnseenViewCameras(const FittedSurface& surface, const TrainingData& data,
                                                   const ViewRayOptions& options) {
  const Vec3d& pivot = surface.pivot;
  const Vec3d& up = surface.up;
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

std::vector<ViewRay> FaceModelViewRays(const FittedSurface& surface, const TrainingData& data,
                                       const ViewRayOptions& options, const Executor& executor) {
  const std::vector<std::vector<Camera>> cameras = UnseenViewCameras(surface, data, options);
  std::vector<ViewRay> out;
  for (int k = 0; k < data.num_frames(); ++k) {
    const std::array<Vec3f, 68> landmarks = surface.Landmarks(k);
    for (const Camera& camera : cameras[k]) {
      std::vector<Vec2f> projected(landmarks.size(), Vec2f::Constant(kNaN));
      for (size_t i = 0; i < landmarks.size(); ++i)
        if (const auto p = camera.Project(landmarks[i].cast<double>())) projected[i] = p->uv.cast<float>();
      if (options.region == ViewRayOptions::Region::kUpper)  // drop the mouth (iBUG 48-67)
        for (size_t i = 48; i < projected.size(); ++i) projected[i] = Vec2f::Constant(kNaN);
      const int width = camera.width(), height = camera.height();
      const Image region = ExpressionRegion(width, height, projected, {}, DefaultRegionDilation(width));
      const Image hull = options.region == ViewRayOptions::Region::kFace
                             ? LandmarkHullRegion(width, height, projected)
                             : Image(width, height, 1, 0.f);
      std::vector<int64_t> pixels;
      for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
          if (region.At(x, y, 0) > 0.f || hull.At(x, y, 0) > 0.f) pixels.push_back(int64_t(y) * width + x);
      const std::vector<float> depth = surface.Depths(camera, k, pixels, executor);
      for (size_t i = 0; i < pixels.size(); ++i)
        if (std::isfinite(depth[i]))
          out.push_back(
              ViewRay{camera.PixelRay(int(pixels[i] % width), int(pixels[i] / width)), int32_t(k), depth[i]});
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
