#include "icef/synth/ground_truth_renderer.h"

#include <cmath>
#include <sstream>

namespace icef::synth {

Status RenderOptions::Validate() const {
  if (supersample < 1 || supersample > 8)
    return Status::Error("supersample: expected 1..8, got " + std::to_string(supersample));
  if (!light_direction.allFinite() || light_direction.norm() < 1e-6f)
    return Status::Error("light_direction: expected a non-zero finite vector");
  if (!(ambient >= 0.f) || !(diffuse >= 0.f)) return Status::Error("ambient/diffuse: expected values >= 0");
  if (!(fill >= 0.f) || !(specular >= 0.f)) return Status::Error("fill/specular: expected values >= 0");
  if (fill > 0.f && (!fill_direction.allFinite() || fill_direction.norm() < 1e-6f))
    return Status::Error("fill_direction: expected a non-zero finite vector");
  if (!(shininess >= 1.f && shininess <= 1000.f)) return Status::Error("shininess: expected 1..1000");
  if (max_steps < 8) return Status::Error("max_steps: expected >= 8, got " + std::to_string(max_steps));
  return Status::Ok();
}

std::string RenderOptions::ToString() const {
  std::ostringstream os;
  os << "RenderOptions(supersample=" << supersample << ", light=[" << light_direction.transpose()
     << "], ambient=" << ambient << ", diffuse=" << diffuse;
  if (fill > 0.f) os << ", fill=" << fill << "@[" << fill_direction.transpose() << "]";
  if (specular > 0.f) os << ", specular=" << specular << "^" << shininess;
  if (canonical_shading) os << ", canonical_shading";
  os << ", max_steps=" << max_steps << ")";
  return os.str();
}

Image RenderGroundTruth(const HeadModel& head, const Camera& camera, const std::vector<float>& expression,
                        const Executor& executor, const RenderOptions& options) {
  const Status valid = options.Validate();
  ICEF_CHECK(valid.ok(), valid.message());
  const face::FaceModel& face_model = head.face();
  const face::ExpressionState state = face_model.Prepare(expression);
  const face::ExpressionState neutral = face_model.Prepare(std::vector<float>(expression.size(), 0.f));
  const Aabb bounds = face_model.Bounds();
  const Vec3f light = options.light_direction.normalized();
  const Vec3f fill_light = options.fill > 0.f ? Vec3f(options.fill_direction.normalized()) : Vec3f::Zero();
  const int w = camera.width(), h = camera.height(), ss = options.supersample;
  Image image(w, h, 4);
  ParallelForChunks(executor, h, 2, [&](int64_t row_begin, int64_t row_end) {
    for (int y = static_cast<int>(row_begin); y < row_end; ++y) {
      for (int x = 0; x < w; ++x) {
        Vec3f sum = Vec3f::Zero();
        int hits = 0;
        for (int sy = 0; sy < ss; ++sy) {
          for (int sx = 0; sx < ss; ++sx) {
            const Ray ray = camera.RayThrough(x + (sx + 0.5) / ss, y + (sy + 0.5) / ss);
            const auto interval = bounds.Intersect(ray);
            if (!interval) continue;
            const float t =
                face_model.Trace(ray, interval->t_near, interval->t_far, state, options.max_steps);
            if (t < 0.f) continue;
            const Vec3f p = ray.At(t);
            const face::FaceModel::Sample sample = face_model.Evaluate(p, state);
            const Vec3f albedo = head.Albedo(sample, p, state);
            const Vec3f normal = options.canonical_shading ? face_model.Normal(sample.canonical, neutral)
                                                           : face_model.Normal(p, state);
            const float lambert = std::max(0.f, normal.dot(light));
            float shade = options.ambient + options.diffuse * lambert;
            if (options.fill > 0.f) shade += options.fill * std::max(0.f, normal.dot(fill_light));
            Vec3f rgb = albedo * shade;
            if (options.specular > 0.f && sample.material != face::Material::kMouthCavity && lambert > 0.f) {
              const Vec3f half = (light - ray.direction.normalized()).normalized();
              rgb += Vec3f::Constant(options.specular *
                                     std::pow(std::max(0.f, normal.dot(half)), options.shininess));
            }
            sum += rgb;
            ++hits;
          }
        }
        const float alpha = static_cast<float>(hits) / (ss * ss);
        const Vec3f rgb = hits > 0 ? Vec3f(sum / hits) : options.background;
        for (int c = 0; c < 3; ++c) image.At(x, y, c) = std::clamp(rgb[c], 0.f, 1.f);
        image.At(x, y, 3) = alpha;
      }
    }
  });
  return image;
}

LandmarkView ProjectLandmarks(const HeadModel& head, const Camera& camera,
                              const std::vector<float>& expression) {
  const face::FaceModel& face_model = head.face();
  const face::ExpressionState state = face_model.Prepare(expression);
  const std::array<Vec3f, 68> points = face_model.Landmarks(state);
  const Vec3f eye = camera.Center().cast<float>();
  const Aabb bounds = face_model.Bounds();
  LandmarkView view;
  for (const Vec3f& p : points) {
    view.landmarks_3d.push_back(p);
    const auto projection = camera.Project(p.cast<double>());
    bool visible = false;
    Vec2f uv(-1.f, -1.f);
    if (projection) {
      uv = projection->uv.cast<float>();
      visible = uv.x() >= 0.f && uv.y() >= 0.f && uv.x() <= camera.width() && uv.y() <= camera.height();
      if (visible) {
        Ray ray;
        ray.direction = (eye - p).normalized();
        ray.origin = p + 0.02f * ray.direction;
        const auto interval = bounds.Intersect(ray);
        if (interval) visible = face_model.Trace(ray, interval->t_near, interval->t_far, state) < 0.f;
      }
    }
    view.landmarks_2d.push_back(uv);
    view.visible.push_back(visible);
  }
  return view;
}

}  // namespace icef::synth
