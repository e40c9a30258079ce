#include "icef/model/prior_light.h"

#include <ceres/ceres.h>

#include <array>
#include <limits>
#include <sstream>

#include "icef/face/face_model.h"
#include "icef/face/ict_warp.h"
#include "icef/face/mesh_depth.h"

namespace icef {

namespace {

// Fewer face-skin pixels than this (images of a few dozen pixels) give no light.
constexpr size_t kMinPixels = 100;

struct SkinPixel {
  Vec3f normal;  // world frame
  Vec3f color;
};

// Residual of one pixel: rho (1 + max(0, n . v)) - c, per channel.
struct ShadingResidual {
  SkinPixel p;
  template <typename T>
  bool operator()(const T* rho, const T* v, T* out) const {
    const T l = T(p.normal.x()) * v[0] + T(p.normal.y()) * v[1] + T(p.normal.z()) * v[2];
    const T s = T(1) + (l > T(0) ? l : T(0));
    for (int a = 0; a < 3; ++a) out[a] = rho[a] * s - T(p.color[a]);
    return true;
  }
};

// The skin pixels of one frame (every `stride`-th pixel in each direction).
std::vector<SkinPixel> SkinPixels(const Frame& frame, const Image& image, const face::FaceModel& model,
                                  const face::Similarity& head_from_world, int stride,
                                  const Executor& executor) {
  const Camera& camera = frame.camera;
  std::vector<float> beta(frame.expression);
  for (float& b : beta) b = std::isfinite(b) ? std::max(b, 0.f) : 0.f;
  const face::ExpressionState state = model.Prepare(beta);
  const Aabb bounds = model.Bounds();
  const Mat3f rot = head_from_world.rotation.cast<float>();
  const float scale = static_cast<float>(head_from_world.scale);
  const Vec3f trans = head_from_world.translation.cast<float>();
  // The face's box in the canonical head frame: the neutral landmarks' extent in x and y, and in z
  // no further back than the jaw line's landmarks.
  Vec3f face_lo = Vec3f::Constant(std::numeric_limits<float>::infinity());
  Vec3f face_hi = -face_lo;
  for (const Vec3f& q : model.NeutralLandmarks()) {
    face_lo = face_lo.cwiseMin(q);
    face_hi = face_hi.cwiseMax(q);
  }
  const int w = camera.width(), h = camera.height();
  const int rows = (h + stride - 1) / stride;
  std::vector<std::vector<SkinPixel>> per_row(rows);
  ParallelFor(executor, rows, [&](int64_t r0, int64_t r1, int) {
    for (int64_t r = r0; r < r1; ++r) {
      const int y = static_cast<int>(r) * stride;
      for (int x = 0; x < w; x += stride) {
        if (image.channels == 4 && image.At(x, y, 3) < 0.99f) continue;
        const Ray world = camera.RayThrough(x + 0.5, y + 0.5);
        Ray ray;
        ray.origin = scale * (rot * world.origin) + trans;
        ray.direction = (rot * world.direction).normalized();
        const auto interval = bounds.Intersect(ray);
        if (!interval) continue;
        const float t = model.Trace(ray, interval->t_near, interval->t_far, state);
        if (t < 0.f) continue;
        const Vec3f p = ray.At(t);
        const face::FaceModel::Sample sample = model.Evaluate(p, state);
        if (sample.material != face::Material::kSkin) continue;
        // The face alone, between the jaw line's sides, the chin and the brows, in front of the
        // ears: hair and the back of the head vary in colour far more than shading does.
        const Vec3f& c = sample.canonical;
        if (c.x() < face_lo.x() || c.x() > face_hi.x() || c.y() < face_lo.y() || c.y() > face_hi.y() ||
            c.z() < face_lo.z())
          continue;
        const Vec3f n_head = model.Normal(p, state);
        if (-n_head.dot(ray.direction) < 0.3f)
          continue;  // grazing: the silhouette, where the fit is least sure
        SkinPixel s;
        s.normal = rot.transpose() * n_head;
        for (int a = 0; a < 3; ++a) s.color[a] = image.At(x, y, a);
        per_row[r].push_back(s);
      }
    }
  });
  std::vector<SkinPixel> out;
  for (auto& row : per_row) out.insert(out.end(), row.begin(), row.end());
  return out;
}

}  // namespace

std::string PriorLightFit::BriefReport() const {
  std::ostringstream os;
  os.precision(3);
  os << "light [" << light.x() << ", " << light.y() << ", " << light.z() << "] (strength " << light.norm()
     << "), skin albedo [" << albedo.x() << ", " << albedo.y() << ", " << albedo.z() << "], " << pixels
     << " skin pixels, RMS residual " << rms;
  return os.str();
}

namespace {

// The skin pixels of every training frame, by `skin(frame, image, stride)`.
template <class SkinFn>
Result<std::vector<SkinPixel>> DatasetSkinPixels(const Dataset& dataset, SkinFn&& skin) {
  if (dataset.train.empty())
    return Status::Error(dataset.root.string() + ": no training frames to fit the light to");
  std::vector<SkinPixel> pixels;
  for (const Frame& frame : dataset.train) {
    ICEF_ASSIGN_OR_RETURN(const Image image, LoadFrameImage(dataset, frame));
    const int stride = std::max(1, frame.camera.width() / 128);
    std::vector<SkinPixel> p = skin(frame, image, stride);
    pixels.insert(pixels.end(), p.begin(), p.end());
  }
  return pixels;
}

// ICT-FaceKit's skin pixels of one frame (every `stride`-th pixel in each direction): the first hit
// of the pixel's ray on the posed mesh (face/mesh_depth.h) is on the face part, its canonical point
// (the same barycentric point of the neutral) inside the neutral landmarks' box as above, and the
// interpolated vertex normal faces the camera.
std::vector<SkinPixel> IctSkinPixels(const Frame& frame, const Image& image, const face::IctWarp& warp,
                                     const IctFaceFit& fit, int stride) {
  const face::IctModel& model = warp.model();
  std::vector<float> beta(frame.expression);
  for (float& b : beta) b = std::isfinite(b) ? std::max(b, 0.f) : 0.f;
  beta.resize(model.num_expressions(), 0.f);
  const std::vector<Vec3f> posed = model.Mesh(fit.identity, beta);
  const std::vector<Vec3f> normals = warp.VertexNormals(posed);
  const face::Similarity& s = fit.head_from_world;
  std::vector<Vec3f> world;
  for (const Vec3f& p : posed) world.push_back(s.ApplyInverse(p.cast<double>()).cast<float>());
  std::vector<int32_t> hit;
  const std::vector<float> depth = face::MeshDepthImage(world, warp.triangles(), frame.camera, &hit);
  Vec3f face_lo = Vec3f::Constant(std::numeric_limits<float>::infinity());
  Vec3f face_hi = -face_lo;
  for (const Vec3f& q : model.Landmarks(warp.neutral())) {
    face_lo = face_lo.cwiseMin(q);
    face_hi = face_hi.cwiseMax(q);
  }
  const int face = model.PartIndex("face");
  const Mat3f world_from_head = s.rotation.transpose().cast<float>();
  std::vector<SkinPixel> out;
  const int w = frame.camera.width(), h = frame.camera.height();
  for (int y = 0; y < h; y += stride)
    for (int x = 0; x < w; x += stride) {
      const size_t i = size_t(y) * w + x;
      if (hit[i] < 0 || (image.channels == 4 && image.At(x, y, 3) < 0.99f)) continue;
      const auto& t = warp.triangles()[hit[i]];
      if (model.part_labels()[t[0]] != face) continue;
      // The hit's barycentric coordinates on the posed triangle (head frame).
      const Ray ray = frame.camera.PixelRay(x, y);
      const Vec3d p = s.Apply(ray.At(depth[i]).cast<double>());
      const Vec3d a = posed[t[0]].cast<double>(), e1 = posed[t[1]].cast<double>() - a,
                  e2 = posed[t[2]].cast<double>() - a, q = p - a;
      const double d11 = e1.dot(e1), d12 = e1.dot(e2), d22 = e2.dot(e2), det = d11 * d22 - d12 * d12;
      if (!(det > 0)) continue;
      const double b1 = (d22 * q.dot(e1) - d12 * q.dot(e2)) / det,
                   b2 = (d11 * q.dot(e2) - d12 * q.dot(e1)) / det;
      const Vec3f b(float(1 - b1 - b2), float(b1), float(b2));
      const Vec3f c = b[0] * warp.neutral()[t[0]] + b[1] * warp.neutral()[t[1]] + b[2] * warp.neutral()[t[2]];
      if (c.x() < face_lo.x() || c.x() > face_hi.x() || c.y() < face_lo.y() || c.y() > face_hi.y() ||
          c.z() < face_lo.z())
        continue;
      const Vec3f n_head = (b[0] * normals[t[0]] + b[1] * normals[t[1]] + b[2] * normals[t[2]]).normalized();
      const Vec3f n = world_from_head * n_head;
      if (-n.dot(ray.direction) < 0.3f) continue;  // grazing
      SkinPixel sp;
      sp.normal = n;
      for (int ch = 0; ch < 3; ++ch) sp.color[ch] = image.At(x, y, ch);
      out.push_back(sp);
    }
  return out;
}

Result<PriorLightFit> FitLightToPixels(const std::vector<SkinPixel>& pixels, const Dataset& dataset);

}  // namespace

Result<PriorLightFit> FitPriorLight(const Dataset& dataset, const face::FaceFit& fit,
                                    const Executor& executor) {
  const face::FaceModel model(fit.shape, fit.style);
  ICEF_ASSIGN_OR_RETURN(const std::vector<SkinPixel> pixels,
                        DatasetSkinPixels(dataset, [&](const Frame& frame, const Image& image, int stride) {
                          return SkinPixels(frame, image, model, fit.head_from_world, stride, executor);
                        }));
  return FitLightToPixels(pixels, dataset);
}

Result<PriorLightFit> FitPriorLight(const Dataset& dataset, const IctFaceFit& fit) {
  ICEF_ASSIGN_OR_RETURN(const std::shared_ptr<const face::IctModel> model, face::IctModel::LoadDefault());
  ICEF_ASSIGN_OR_RETURN(const face::IctWarp warp, face::IctWarp::Create(*model, fit.identity));
  ICEF_ASSIGN_OR_RETURN(const std::vector<SkinPixel> pixels,
                        DatasetSkinPixels(dataset, [&](const Frame& frame, const Image& image, int stride) {
                          return IctSkinPixels(frame, image, warp, fit, stride);
                        }));
  return FitLightToPixels(pixels, dataset);
}

namespace {

Result<PriorLightFit> FitLightToPixels(const std::vector<SkinPixel>& pixels, const Dataset& dataset) {
  if (pixels.size() < kMinPixels)
    return Status::Error(dataset.root.string() + ": only " + std::to_string(pixels.size()) +
                         " training pixels show the fitted face model's face skin (fewer than " +
                         std::to_string(kMinPixels) + "); too few to fit the light");
  Vec3f mean_color = Vec3f::Zero(), mean_normal = Vec3f::Zero();
  for (const SkinPixel& p : pixels) {
    mean_color += p.color;
    mean_normal += p.normal;
  }
  mean_color /= static_cast<float>(pixels.size());
  mean_normal = mean_normal.normalized();
  // Starting lights: towards the mean normal (the cameras' side), and each axis direction.
  std::vector<Vec3f> starts = {mean_normal};
  for (int a = 0; a < 3; ++a)
    for (float sign : {1.f, -1.f}) starts.push_back(sign * Vec3f::Unit(a));
  PriorLightFit best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (const Vec3f& start : starts) {
    std::array<double, 3> rho{mean_color.x() / 1.5, mean_color.y() / 1.5, mean_color.z() / 1.5};
    std::array<double, 3> v{start.x(), start.y(), start.z()};
    ceres::Problem problem;
    for (const SkinPixel& p : pixels)
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<ShadingResidual, 3, 3, 3>(new ShadingResidual{p}),
          new ceres::HuberLoss(0.05), rho.data(), v.data());
    ceres::Solver::Options options;
    options.max_num_iterations = 50;
    options.num_threads = 1;  // the same result for any thread count
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    if (summary.final_cost < best_cost) {
      best_cost = summary.final_cost;
      best.light = Vec3f(float(v[0]), float(v[1]), float(v[2]));
      best.albedo = Vec3f(float(rho[0]), float(rho[1]), float(rho[2]));
    }
  }
  double sq = 0;
  for (const SkinPixel& p : pixels) {
    const float s = 1.f + std::max(0.f, p.normal.dot(best.light));
    sq += (best.albedo * s - p.color).squaredNorm();
  }
  best.pixels = static_cast<int>(pixels.size());
  best.rms = std::sqrt(sq / (3.0 * pixels.size()));
  return best;
}

}  // namespace

}  // namespace icef
