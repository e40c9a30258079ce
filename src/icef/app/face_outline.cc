#include "icef/app/face_outline.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "icef/face/expression.h"
#include "icef/face/face_model.h"

namespace icef {

namespace {

void Plot(Image* image, int x, int y, int thickness, const Vec3f& colour) {
  for (int dy = 0; dy < thickness; ++dy)
    for (int dx = 0; dx < thickness; ++dx) {
      const int px = x + dx, py = y + dy;
      if (px < 0 || py < 0 || px >= image->width || py >= image->height) continue;
      for (int c = 0; c < std::min(3, image->channels); ++c) image->At(px, py, c) = colour[c];
      if (image->channels == 4) image->At(px, py, 3) = 1.f;
    }
}

void Line(Image* image, const Vec2d& a, const Vec2d& b, int thickness, const Vec3f& colour) {
  const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() * 2.0)));
  for (int i = 0; i <= steps; ++i) {
    const Vec2d p = a + (b - a) * (double(i) / steps);
    Plot(image, static_cast<int>(std::floor(p.x())), static_cast<int>(std::floor(p.y())), thickness, colour);
  }
}

struct Run {
  int first, last;
  bool closed;
};
// The iBUG-68 groups.
constexpr Run kRuns[] = {{0, 16, false}, {17, 21, false}, {22, 26, false}, {27, 30, false}, {31, 35, false},
                         {36, 41, true}, {42, 47, true},  {48, 59, true},  {60, 67, true}};

}  // namespace

std::array<Vec3f, 68> FittedLandmarks(const face::FaceFit& fit, std::span<const float> beta) {
  const face::FaceModel model(fit.shape, fit.style);
  std::vector<float> b(beta.begin(), beta.end());
  for (float& v : b) v = std::isfinite(v) ? std::max(v, 0.f) : 0.f;
  std::array<Vec3f, 68> lm = model.Landmarks(model.Prepare(b));
  for (Vec3f& p : lm) p = fit.head_from_world.ApplyInverse(p.cast<double>()).cast<float>();
  return lm;
}

void DrawFaceOutline(Image* image, const Camera& camera, std::span<const Vec3f> landmarks_world,
                     const Vec3f& colour) {
  // Camera::Project works in the camera's pixel units; the image may be another size.
  const double sx = double(image->width) / camera.width(), sy = double(image->height) / camera.height();
  std::vector<std::optional<Vec2d>> uv;
  for (const Vec3f& p : landmarks_world) {
    const auto proj = camera.Project(p.cast<double>());
    uv.push_back(proj ? std::optional<Vec2d>(Vec2d(proj->uv.x() * sx, proj->uv.y() * sy)) : std::nullopt);
  }
  DrawFaceOutline2d(image, uv, colour);
}

void DrawFaceOutline2d(Image* image, std::span<const std::optional<Vec2d>> uv, const Vec3f& colour) {
  const int thickness = image->width >= 256 ? 2 : 1;
  for (const Run& run : kRuns) {
    if (run.last >= static_cast<int>(uv.size())) continue;
    for (int i = run.first; i <= run.last; ++i) {
      const int j = i < run.last ? i + 1 : (run.closed ? run.first : -1);
      if (j < 0 || !uv[i] || !uv[j]) continue;
      Line(image, *uv[i], *uv[j], thickness, colour);
    }
  }
}

}  // namespace icef
