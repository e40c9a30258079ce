// Ground-truth rendering of the procedural head: sphere tracing of the warped SDF, Lambertian
// shading with a key light fixed to the head frame plus ambient (and optionally a second light and
// a specular sheen), 2x2 (configurable) supersampling,
// RGBA output whose alpha is the coverage mask and whose RGB is the covered samples' mean colour
// (background where nothing is hit), and landmark projection with an occlusion test.
#pragma once

#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/io/image.h"
#include "icef/math/camera.h"
#include "icef/synth/head_model.h"

namespace icef::synth {

struct RenderOptions {
  // Samples per pixel along each axis (2 = 2x2 supersampling).
  int supersample = 2;
  // Direction towards the light, head frame (normalised when used): upper left-front of the face.
  Vec3f light_direction = Vec3f(-0.35f, 0.45f, 0.82f);
  // Ambient term added to the Lambertian term.
  float ambient = 0.38f;
  // Lambertian (diffuse) light intensity.
  float diffuse = 0.72f;
  // A second light (fill or rim), head frame, Lambertian with intensity `fill` (0: none).
  Vec3f fill_direction = Vec3f(0.6f, 0.1f, 0.5f);
  float fill = 0.f;
  // A soft white specular sheen on skin, lips, lids and eyes (Blinn-Phong from the key light:
  // specular * max(0, n.h)^shininess; 0: matte). It depends on the view, as real skin does.
  float specular = 0.f;
  float shininess = 24.f;
  // Background RGB where no surface is hit (RGB of alpha-0 pixels).
  Vec3f background = Vec3f::Ones();
  // Maximum sphere-tracing steps per ray.
  int max_steps = 192;
  // Shade each surface point with the neutral surface's normal at its canonical point instead of
  // its own: the shading moves with the skin, unchanged by the expression, as a model whose
  // canonical colours are fixed (a warp of a static field) renders it. A reference for what a
  // deformation alone can reproduce (scripts/expr_gain_probe.py), not a realistic render.
  bool canonical_shading = false;

  Status Validate() const;
  std::string ToString() const;
};

// The RGBA image of the head at `expression` ([face::kNumExpressions] weights) seen by `camera`.
// Deterministic: pixels are independent, so the result does not depend on the thread count.
Image RenderGroundTruth(const HeadModel& head, const Camera& camera, const std::vector<float>& expression,
                        const Executor& executor = Executor(),
                        const RenderOptions& options = RenderOptions());

// Landmarks of one view: 3D (head frame), 2D (pixels, +0.5 centres) and visibility.
struct LandmarkView {
  std::vector<Vec3f> landmarks_3d;
  std::vector<Vec2f> landmarks_2d;
  // False when the landmark is behind the camera, outside the image, or occluded: a shadow ray
  // from the landmark (started 0.02 head units towards the camera) to the camera centre hits the
  // surface.
  std::vector<bool> visible;
};
LandmarkView ProjectLandmarks(const HeadModel& head, const Camera& camera,
                              const std::vector<float>& expression);

}  // namespace icef::synth
