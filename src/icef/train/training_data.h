// The training frames of a dataset held in memory for ray sampling: cameras, target colours
// composited over the dataset's background, and alpha where the images have it.
#pragma once

#include <vector>

#include "icef/core/rng.h"
#include "icef/data/dataset.h"
#include "icef/model/avatar_model.h"

namespace icef {

// How SampleBatch draws a step's rays.
struct RaySampling {
  // Each ray's target over a random colour that the model also renders over (images with alpha).
  bool random_background = false;
  // Each ray through a uniformly random point of its pixel (the target is the pixel's average),
  // else through the pixel centre.
  bool jitter = false;
  // The share of the rays drawn uniformly from the training frames' expression regions (brows,
  // eyes and mouth by their 2D landmarks: data/landmark_region.h); the rest uniformly over all
  // pixels. 0 with no frame with landmarks.
  double region_fraction = 0;
  // Rays appended after the pixel rays, drawn uniformly from the unseen-view pool (SetViewRays):
  // depth targets alone (TrainRays::photo_rays). 0, or an empty pool: none.
  int view_rays = 0;
};

// A ray from an unseen view of a training frame's expression with the fitted face model's depth on it
// (train.depth_prior_views; train/face_depth.h builds them).
struct ViewRay {
  Ray ray;        // world frame
  int32_t frame;  // the training frame whose expression the view shows
  float depth;    // ray parameter t of the face model's surface
};

class TrainingData {
 public:
  // Loads every training image; errors name the image file.
  static Result<TrainingData> Load(const Dataset& dataset);

  int num_frames() const { return static_cast<int>(cameras_.size()); }
  bool has_alpha() const { return has_alpha_; }
  int64_t num_pixels() const { return static_cast<int64_t>(frame_of_pixel_.size()); }
  const Camera& camera(int k) const { return cameras_[k]; }
  const std::vector<Camera>& cameras() const { return cameras_; }
  // Frame k's alpha as a 1-channel image (all ones without alpha).
  Image Alpha(int k) const;

  // Pixels (global indices, frame by frame) in the training frames' expression regions: each
  // frame's ExpressionRegion of its own 2D landmarks, dilated by DefaultRegionDilation. Empty
  // when no frame has landmarks.
  const std::vector<int64_t>& region_pixels() const { return region_pixels_; }
  // The frame of global pixel p and the ray through its centre.
  int frame_of_pixel(int64_t p) const { return frame_of_pixel_[p]; }
  Ray PixelCentreRay(int64_t p) const {
    return cameras_[frame_of_pixel_[p]].PixelRay(pixel_x_[p], pixel_y_[p]);
  }
  // Per-pixel depth targets [num_pixels()] (ray parameter t of the pixel-centre ray, NaN = none) that
  // SampleBatch copies into TrainRays::depth_target; empty (the default) leaves it empty.
  void SetDepthTargets(std::vector<float> depth);
  const std::vector<float>& depth_targets() const { return depth_; }
  // The pool SampleBatch draws RaySampling::view_rays from (empty by default).
  void SetViewRays(std::vector<ViewRay> rays) { view_rays_ = std::move(rays); }
  const std::vector<ViewRay>& view_rays() const { return view_rays_; }
  // The global pixel index of (frame k, x, y).
  int64_t PixelIndex(int k, int x, int y) const {
    return frame_offset_[k] + int64_t(y) * cameras_[k].width() + x;
  }

  // Fills `batch` with `num_rays` rays from Rng(seed, "ray_batch", step): deterministic for
  // (seed, step). The first round(region_fraction * num_rays) are drawn uniformly from
  // region_pixels(), the rest uniformly over all training pixels. With random_background (and
  // alpha), each ray's target is its foreground composited over a random colour that the model
  // also renders over, so the field cannot fake the background with haze (instant-ngp's trick).
  // With view_rays and a pool, that many unseen-view rays follow the num_rays pixel rays (their own
  // stream: the pixel rays are those of a batch without them); batch->photo_rays = num_rays.
  // The same batch for any executor.
  void SampleBatch(int num_rays, uint64_t seed, int64_t step, const RaySampling& how, TrainRays* batch,
                   const Executor& executor) const;

 private:
  std::vector<Camera> cameras_;
  std::vector<int64_t> frame_offset_;       // [K] first global pixel of each frame
  std::vector<int32_t> frame_of_pixel_;     // [P] global pixel -> frame
  std::vector<int32_t> pixel_x_, pixel_y_;  // [P]
  std::vector<float> premultiplied_;        // [P, 3] foreground colour times alpha
  std::vector<float> background_;           // [P, 3] the dataset's background behind each pixel
  std::vector<float> alpha_;                // [P] or empty
  bool has_alpha_ = false;
  std::vector<int64_t> region_pixels_;  // see region_pixels()
  std::vector<float> depth_;            // see SetDepthTargets()
  std::vector<ViewRay> view_rays_;      // see SetViewRays()
};

}  // namespace icef
