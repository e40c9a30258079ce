#include "icef/train/training_data.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "icef/data/landmark_region.h"

namespace icef {

Result<TrainingData> TrainingData::Load(const Dataset& dataset) {
  TrainingData data;
  if (dataset.train.empty()) return Status::Error(dataset.root.string() + ": no training frames");
  Image background_image;
  if (dataset.background_file_path) {
    ICEF_ASSIGN_OR_RETURN(background_image, ReadImage(dataset.root / *dataset.background_file_path));
  }
  bool any_alpha = false, all_alpha = true;
  std::vector<Image> images;
  for (const Frame& frame : dataset.train) {
    ICEF_ASSIGN_OR_RETURN(Image img, LoadFrameImage(dataset, frame));
    any_alpha |= img.HasAlpha();
    all_alpha &= img.HasAlpha();
    images.push_back(std::move(img));
  }
  data.has_alpha_ = any_alpha && all_alpha;
  for (size_t k = 0; k < images.size(); ++k) {
    const Image& img = images[k];
    data.cameras_.push_back(dataset.train[k].camera);
    data.frame_offset_.push_back(static_cast<int64_t>(data.frame_of_pixel_.size()));
    const bool bg_img = !background_image.empty() && background_image.width == img.width &&
                        background_image.height == img.height;
    for (int y = 0; y < img.height; ++y) {
      for (int x = 0; x < img.width; ++x) {
        const Vec3f bg = bg_img ? background_image.Rgb(x, y) : dataset.background;
        const float a = img.HasAlpha() ? img.At(x, y, 3) : 1.f;
        const Vec3f c = a * img.Rgb(x, y);
        data.frame_of_pixel_.push_back(static_cast<int32_t>(k));
        data.pixel_x_.push_back(x);
        data.pixel_y_.push_back(y);
        data.premultiplied_.insert(data.premultiplied_.end(), {c.x(), c.y(), c.z()});
        data.background_.insert(data.background_.end(), {bg.x(), bg.y(), bg.z()});
        if (data.has_alpha_) data.alpha_.push_back(a);
      }
    }
    if (dataset.train[k].landmarks_2d) {
      const Image region = ExpressionRegion(img.width, img.height, *dataset.train[k].landmarks_2d, {},
                                            DefaultRegionDilation(img.width));
      for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
          if (region.At(x, y, 0) > 0.f)
            data.region_pixels_.push_back(data.PixelIndex(static_cast<int>(k), x, y));
    }
  }
  return data;
}

Image TrainingData::Alpha(int k) const {
  const Camera& cam = cameras_[k];
  Image out(cam.width(), cam.height(), 1, 1.f);
  if (has_alpha_)
    std::copy(alpha_.begin() + frame_offset_[k], alpha_.begin() + frame_offset_[k] + out.pixels.size(),
              out.pixels.begin());
  return out;
}

void TrainingData::SetDepthTargets(std::vector<float> depth) {
  ICEF_CHECK(depth.empty() || depth.size() == frame_of_pixel_.size(),
             "depth targets: one per training pixel");
  depth_ = std::move(depth);
}

void TrainingData::SampleBatch(int num_rays, uint64_t seed, int64_t step, const RaySampling& how,
                               TrainRays* batch, const Executor& executor) const {
  const int extra = view_rays_.empty() ? 0 : std::max(how.view_rays, 0);
  const int all_rays = num_rays + extra;
  batch->photo_rays = extra > 0 ? num_rays : -1;
  batch->rays.resize(all_rays);
  batch->frame.resize(all_rays);
  batch->target_rgb.assign(3 * size_t(all_rays), 0.f);
  batch->target_alpha.assign(has_alpha_ ? all_rays : 0, 0.f);
  batch->background.resize(3 * size_t(all_rays));
  batch->depth_target.assign(depth_.empty() && extra == 0 ? 0 : all_rays,
                             std::numeric_limits<float>::quiet_NaN());
  const bool random = how.random_background && has_alpha_;
  const bool jitter = how.jitter;
  // The draws in ray order on the caller (three streams, each consumed in order), then the rays and
  // targets in parallel: the same batch for any thread count.
  Rng rng(seed, StreamId("ray_batch"), uint64_t(step));
  Rng bg_rng(seed, StreamId("random_background"), uint64_t(step));
  Rng jitter_rng(seed, StreamId("pixel_jitter"), uint64_t(step));
  const uint64_t total = frame_of_pixel_.size();
  struct PixelDraw {
    uint64_t pixel;
    double ju, jv;
  };
  std::vector<PixelDraw> draws(num_rays);
  const int from_region =
      region_pixels_.empty()
          ? 0
          : static_cast<int>(std::lround(std::clamp(how.region_fraction, 0.0, 1.0) * num_rays));
  for (int r = 0; r < num_rays; ++r) {
    PixelDraw& d = draws[r];
    d.pixel = r < from_region ? uint64_t(region_pixels_[rng.Below(region_pixels_.size())]) : rng.Below(total);
    d.ju = jitter ? jitter_rng.Uniform() : 0.5;
    d.jv = jitter ? jitter_rng.Uniform() : 0.5;
    for (int a = 0; a < 3 && random; ++a) batch->background[3 * r + a] = static_cast<float>(bg_rng.Uniform());
  }
  ParallelFor(executor, num_rays, [&](int64_t r0, int64_t r1, int) {
    for (int64_t r = r0; r < r1; ++r) {
      const PixelDraw& d = draws[r];
      const uint64_t p = d.pixel;
      const int k = frame_of_pixel_[p];
      batch->frame[r] = k;
      // The target is the pixel's average colour, so the ray goes through a random point of the pixel.
      batch->rays[r] = cameras_[k].RayThrough(pixel_x_[p] + d.ju, pixel_y_[p] + d.jv);
      const float alpha = has_alpha_ ? alpha_[p] : 1.f;
      for (int a = 0; a < 3; ++a) {
        const float bg = random ? batch->background[3 * r + a] : background_[3 * p + a];
        batch->background[3 * r + a] = bg;
        batch->target_rgb[3 * r + a] = premultiplied_[3 * p + a] + (1.f - alpha) * bg;
      }
      if (has_alpha_) batch->target_alpha[r] = alpha;
      // The target is the centre ray's depth; a jittered ray is within a pixel of it.
      if (!depth_.empty()) batch->depth_target[r] = depth_[p];
    }
  });
  // The unseen-view rays: no colour to match, only the face model's depth.
  Rng view_rng(seed, StreamId("view_rays"), uint64_t(step));
  for (int r = num_rays; r < all_rays; ++r) {
    const ViewRay& v = view_rays_[view_rng.Below(view_rays_.size())];
    batch->rays[r] = v.ray;
    batch->frame[r] = v.frame;
    batch->depth_target[r] = v.depth;
    for (int a = 0; a < 3; ++a) batch->background[3 * r + a] = background_[a];
  }
}

}  // namespace icef
