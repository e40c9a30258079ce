// The fitted face model drawn over an image (icef render, icef mask): its 68 landmarks at an
// expression, carried into the dataset's world frame and projected through a camera, joined into
// the usual iBUG-68 outline (jaw, brows, nose, eyes, outer and inner lips).
#pragma once

#include <array>
#include <optional>
#include <span>

#include "icef/face/face_fit.h"
#include "icef/io/image.h"
#include "icef/math/camera.h"

namespace icef {

// The fitted face model's landmarks at expression beta (face-model order, negative weights act as
// zero), world frame.
std::array<Vec3f, 68> FittedLandmarks(const face::FaceFit& fit, std::span<const float> beta);

// Draws the outline (1-pixel lines, 2 pixels from 256 px up) in `colour` onto an RGB or RGBA image.
void DrawFaceOutline(Image* image, const Camera& camera, std::span<const Vec3f> landmarks_world,
                     const Vec3f& colour);

// The same outline through 68 points already in the image's coordinates (nullopt: not drawn).
void DrawFaceOutline2d(Image* image, std::span<const std::optional<Vec2d>> uv, const Vec3f& colour);

}  // namespace icef
