// The foreground mask of a tracked photo: GrabCut (OpenCV) seeded by the fitted head's silhouette.
// Well inside the silhouette is sure foreground, the rest of it probable foreground, a band around
// it probable background, everything farther (and what lies outside the photo) sure background;
// GrabCut's colour models then move the boundary onto the image's own edges (hair beyond the
// skull, the neck). Where a person segmentation is given (person_segmentation.h), what it calls
// background with confidence is sure background too, unless deep inside the silhouette: GrabCut's
// colour models alone keep background that resembles hair or skin (a door frame beside dark hair);
// what it calls the person within the band around the silhouette is probable foreground (hair as
// dark as the background behind it).
// The largest connected component, holes filled, is the mask.
#pragma once

#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/face/face_model.h"
#include "icef/io/image.h"
#include "icef/math/camera.h"

namespace icef::track {

struct HeadMaskOptions {
  double sure_inside =
      0.04;            // silhouette pixels deeper than this (fraction of the image width) are sure foreground
  double band = 0.12;  // outside pixels within this distance of the silhouette are probable background
  int iterations = 5;  // GrabCut iterations
  double person_background =
      0.05;  // person probability below which a pixel outside the sure core is sure background
  double person_foreground =
      0.5;  // person probability above which a pixel in the band is probable foreground (hair)

  Status Validate() const;
  std::string ToString() const;
};

// 1-channel image, 1 where the face model at `expression` covers the pixel (world = head frame).
Image HeadSilhouette(const face::FaceModel& model, const std::vector<float>& expression, const Camera& camera,
                     const Executor& executor = Executor(1));

// The mask (1-channel, 0 or 1) of `image` (RGB or RGBA; alpha ignored). `outside` (1-channel, may be
// empty) marks pixels that lie outside the original photo; `person` (1-channel, may be empty) is a
// person segmentation's probability per pixel. Deterministic.
Image HeadMask(const Image& image, const Image& silhouette, const Image& outside,
               const Image& person = Image(), const HeadMaskOptions& options = {});

// The mask (1-channel, 0 or 1) of the person alone: where `person` (a person segmentation's
// probability) is above `threshold` and the pixel lies inside the photo (`outside`, may be empty),
// the largest component with its holes filled. Shoulders, arms and whatever the network counts as
// the person are in it.
Image PersonMask(const Image& person, const Image& outside, double threshold = 0.5);

// The mask (1-channel, 0 or 1) of what a frame shows in front of a known background image (NerFace's
// static camera: bg/ holds the empty scene): pixels whose colour differs from the background's by
// more than `threshold` in some channel (colours in [0, 1]), opened and closed by a 3x3 disk, the
// largest component with its holes filled. The same size as `background`; RGB or RGBA (alpha
// ignored).
Image BackgroundDifferenceMask(const Image& frame, const Image& background, double threshold = 0.1);

// Points on the edge of `mask` (1-channel, > 0.5 inside), in pixels (pixel centres at +0.5): the
// midpoint between each inside pixel and each of its 4-neighbours outside, leaving out edges at the
// image border and edges touching `outside` (1-channel, may be empty: pixels the photo does not
// cover). At most max_points, evenly spaced in scan order. Deterministic.
std::vector<Vec2f> MaskEdgePoints(const Image& mask, const Image& outside, int max_points);

// The colour of a face's skin: the mean and inverse covariance of (r, g) chromaticity and log
// brightness of the pixels in disks (radius 0.12 IOD) at the cheeks, beside the mouth and on the
// nose bridge, placed from its 68 landmarks (pixels). Invalid (nothing sampled) when the disks miss
// the image.
struct SkinModel {
  Vec3d mean = Vec3d::Zero();
  Mat3d inverse_covariance = Mat3d::Identity();
  bool valid = false;
  // Mahalanobis distance of a colour (RGB in [0, 1]) from the skin's.
  double Distance(const Vec3f& rgb) const;
};
SkinModel FitSkinModel(const Image& image, const std::vector<Vec2f>& landmarks);

// Per edge point of `mask` (MaskEdgePoints): whether the mask's inside just behind it (depth pixels
// along the inward normal, a 3x3 mean) is skin, within max_distance of `skin`. The face's own
// outline is skin against the background; hair over the cheeks, a hat, a collar are not. An
// invalid skin model keeps every point.
std::vector<bool> SkinEdges(const Image& image, const Image& mask, const std::vector<Vec2f>& points,
                            const SkinModel& skin, double depth, double max_distance = 3.0);

// Intersection over union of two masks (> 0.5).
double MaskIou(const Image& a, const Image& b);

}  // namespace icef::track
