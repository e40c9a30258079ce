#include "icef/app/mask_app.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "icef/app/face_outline.h"
#include "icef/data/dataset.h"
#include "icef/field/region_mask.h"
#include "icef/io/image.h"
#include "icef/model/face_prior.h"

namespace icef {

namespace fs = std::filesystem;

namespace {

// Black -> red -> yellow -> white.
Vec3f Heat(float m) {
  m = std::clamp(m, 0.f, 1.f);
  return Vec3f(std::min(1.f, 3.f * m), std::clamp(3.f * m - 1.f, 0.f, 1.f),
               std::clamp(3.f * m - 2.f, 0.f, 1.f));
}

void DrawDot(Image* image, const Vec2d& uv, const Vec3f& colour) {
  const int cx = int(std::floor(uv.x())), cy = int(std::floor(uv.y()));
  const int r = std::max(1, image->width / 128);
  for (int y = cy - r; y <= cy + r; ++y)
    for (int x = cx - r; x <= cx + r; ++x) {
      if (x < 0 || y < 0 || x >= image->width || y >= image->height) continue;
      for (int c = 0; c < 3; ++c) image->At(x, y, c) = colour[c];
    }
}

// Maximum of M along the pixel ray inside the aabb, sampled at half the mask-grid cell size.
float MaxAlongRay(const RegionMask& mask, const Aabb& aabb, const Ray& ray) {
  Aabb box;
  box.min = mask.grid_min().cwiseMax(aabb.min);
  box.max = (mask.grid_min() + mask.grid_resolution().cast<float>().cwiseProduct(mask.grid_cell_size()))
                .cwiseMin(aabb.max);
  if (!box.IsValid()) return 0.f;
  const std::optional<Interval> iv = box.Intersect(ray);
  if (!iv) return 0.f;
  const float step = 0.5f * mask.grid_cell_size().minCoeff();
  float best = 0.f;
  for (float t = iv->t_near; t <= iv->t_far; t += step) best = std::max(best, mask.Evaluate(ray.At(t)));
  return best;
}

Image Slice(const RegionMask& mask, const Aabb& aabb, const Vec3f& centre, int axis_u, int axis_v, int size) {
  const Vec3f extent = aabb.Extent();
  const float scale = float(size) / std::max(extent[axis_u], extent[axis_v]);
  const int w = std::max(1, int(std::round(extent[axis_u] * scale)));
  const int h = std::max(1, int(std::round(extent[axis_v] * scale)));
  Image image(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Vec3f p = centre;
      p[axis_u] = aabb.min[axis_u] + (float(x) + 0.5f) / scale;
      p[axis_v] = aabb.max[axis_v] - (float(y) + 0.5f) / scale;  // row 0 at the top
      const Vec3f c = Heat(mask.Evaluate(p));
      for (int k = 0; k < 3; ++k) image.At(x, y, k) = c[k];
    }
  return image;
}

}  // namespace

Status MaskAppOptions::Validate() const {
  if (dataset.empty()) return Status::Error("a dataset directory is required");
  if (out.empty()) return Status::Error("--out is required");
  return Status::Ok();
}

Status RunMask(const MaskAppOptions& o, const Executor& executor, std::ostream& out) {
  ICEF_RETURN_IF_ERROR(o.Validate());
  ICEF_ASSIGN_OR_RETURN(const Dataset dataset, LoadDataset(o.dataset));
  if (dataset.train.empty()) return Status::Error(o.dataset.string() + ": no training frames");
  if (o.frame < 0 || o.frame >= int(dataset.train.size()))
    return Status::Error("--frame " + std::to_string(o.frame) + " is out of range: the dataset has " +
                         std::to_string(dataset.train.size()) + " training frames");
  ICEF_ASSIGN_OR_RETURN(const RegionMask mask,
                        RegionMask::FromDataset(dataset, RegionMaskOptions(), executor));
  const Frame& frame = dataset.train[o.frame];
  ICEF_ASSIGN_OR_RETURN(const Image loaded, LoadFrameImage(dataset, frame));
  const Image rgb = CompositeOver(loaded, dataset.background);
  std::error_code ec;
  fs::create_directories(o.out, ec);
  if (ec) return Status::Error(o.out.string() + ": cannot create directory: " + ec.message());

  const Camera& camera = frame.camera;
  Image projection(camera.width(), camera.height(), 1);
  ParallelFor(executor, camera.height(), [&](int64_t begin, int64_t end, int) {
    for (int64_t y = begin; y < end; ++y)
      for (int x = 0; x < camera.width(); ++x)
        projection.At(x, int(y), 0) = MaxAlongRay(mask, dataset.aabb, camera.PixelRay(x, int(y)));
  });
  Image overlay(rgb.width, rgb.height, 3);
  const Vec3f red(1.f, 0.1f, 0.05f);
  for (int y = 0; y < rgb.height; ++y)
    for (int x = 0; x < rgb.width; ++x) {
      const float a = 0.6f * projection.At(x, y, 0);
      for (int c = 0; c < 3; ++c) overlay.At(x, y, c) = (1.f - a) * rgb.At(x, y, c) + a * red[c];
    }
  for (int i = 0; i < kNumLandmarks; ++i) {
    const auto p = camera.Project(mask.landmarks()[i].cast<double>());
    if (!p) continue;
    const bool expressive = (i >= 17 && i <= 26) || i >= 36;
    DrawDot(&overlay, p->uv, expressive ? Vec3f(0.1f, 0.9f, 0.1f) : Vec3f(0.1f, 0.3f, 1.f));
  }
  const std::string suffix = "_frame" + std::to_string(o.frame) + ".png";
  const fs::path overlay_path = o.out / ("mask_overlay" + suffix);
  const fs::path projection_path = o.out / ("mask_projection" + suffix);
  ICEF_RETURN_IF_ERROR(WritePng(overlay_path, overlay));
  ICEF_RETURN_IF_ERROR(WritePng(projection_path, projection));

  const Vec3f centre = mask.LandmarkCentroid();
  const struct {
    const char* name;
    int u, v;
  } planes[] = {{"xy", 0, 1}, {"xz", 0, 2}, {"yz", 2, 1}};
  out << "mask: " << mask.source() << "; inter-ocular distance " << mask.inter_ocular_distance()
      << "; landmark centroid [" << centre.x() << ", " << centre.y() << ", " << centre.z() << "]\n";
  out << overlay_path.string() << "\n" << projection_path.string() << "\n";
  if (CheckFaceModelExpressions(dataset.expression_names, o.dataset.string()).ok()) {
    const Result<face::FaceFit> fit = FitFaceModelToDataset(dataset);
    if (fit.ok()) {
      Image outlined = rgb;
      DrawFaceOutline(&outlined, camera, FittedLandmarks(*fit, frame.expression), Vec3f(1.f, 0.85f, 0.1f));
      const fs::path fit_path = o.out / ("fit" + suffix);
      ICEF_RETURN_IF_ERROR(WritePng(fit_path, outlined));
      out << fit->BriefReport() << (fit->Poor() ? " (poor: check the landmarks and expressions)" : "") << "\n"
          << fit_path.string() << "\n";
    } else {
      out << "face model: not fitted (" << fit.status().message() << ")\n";
    }
  }
  for (const auto& plane : planes) {
    const fs::path path = o.out / (std::string("mask_slice_") + plane.name + ".png");
    ICEF_RETURN_IF_ERROR(WritePng(path, Slice(mask, dataset.aabb, centre, plane.u, plane.v, 256)));
    out << path.string() << "\n";
  }
  return Status::Ok();
}

}  // namespace icef
