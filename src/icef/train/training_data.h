// The training frames of a dataset held in memory for ray sampling: cameras, target colours
// composited over the dataset's background, and alpha where the images have it.
#pragma once

#include <vector>

#include "icef/core/rng.h"
#include "icef/data/dataset.h"
#include "icef/model/avatar_model.h"

namespace icef {

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

  // Fills `batch` with `num_rays` rays drawn uniformly over all training pixels, from
  // Rng(seed, "ray_batch", step): deterministic for (seed, step). With random_background (and
  // alpha), each ray's target is its foreground composited over a random colour that the model
  // also renders over, so the field cannot fake the background with haze (instant-ngp's trick).
  // With jitter, each ray passes through a uniformly random point of its pixel (the target is the
  // pixel's average), else through the pixel centre. The same batch for any executor.
  void SampleBatch(int num_rays, uint64_t seed, int64_t step, bool random_background, bool jitter,
                   TrainRays* batch, const Executor& executor) const;

 private:
  std::vector<Camera> cameras_;
  std::vector<int64_t> frame_offset_;    // [K] first global pixel of each frame
  std::vector<int32_t> frame_of_pixel_;  // [P] global pixel -> frame
  std::vector<int32_t> pixel_x_, pixel_y_;  // [P]
  std::vector<float> premultiplied_;        // [P, 3] foreground colour times alpha
  std::vector<float> background_;           // [P, 3] the dataset's background behind each pixel
  std::vector<float> alpha_;                // [P] or empty
  bool has_alpha_ = false;
};

}  // namespace icef
