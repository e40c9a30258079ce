// The tracker's image term (docs/design.md §8): what the photometric refit of track_fit.h needs besides
// the face model. Landmarks alone read expressions poorly (dlib's mouth and lid points barely move
// on some faces); the photos themselves show them. The refit samples points of the subject's
// neutral face (canonical space), carries each into every photo through the face model's warp at
// that photo's expression and pose, and asks the colours found there to agree across photos: where
// the fitted jaw opens less than the true one, the chin's points land on the lips in one photo and
// on the chin in another.
#pragma once

#include <string>
#include <vector>

#include "icef/face/face_model.h"
#include "icef/io/image.h"
#include "icef/math/types.h"

namespace icef::track {

// An RGB photo blurred by a Gaussian, sampled bilinearly at pixel coordinates with +0.5 centres
// (data/dataset.h's convention). The blur widens the basin of the colour residuals.
class BlurredImage {
 public:
  BlurredImage() = default;
  // image: 3 or 4 channels (alpha ignored); sigma_px: the Gaussian's standard deviation (0: none).
  BlurredImage(const Image& image, double sigma_px);

  int width() const { return width_; }
  int height() const { return height_; }
  // The colour at (u, v); false (and `rgb` untouched) outside the image's pixel centres.
  bool Sample(double u, double v, Vec3d* rgb) const;
  std::string ToString() const;

 private:
  int width_ = 0, height_ = 0;
  std::vector<float> rgb_;  // [height, width, 3]
};

// About `count` points on the neutral face of `model` (head frame, canonical space), seen from the
// front on a regular grid: skin between the chin and the brows' top, inside the jaw line, without
// the eyes (eyeball, lids and a margin around them: a closing lid is a slide, not a warp) and the
// mouth's cavity. Deterministic.
std::vector<Vec3f> CanonicalFaceSamples(const face::FaceModel& model, int count);

}  // namespace icef::track
