// A triangle mesh seen by a camera: for every pixel, the ray parameter at which the ray through the
// pixel's centre first meets the mesh (math/camera.h's PixelRay: t is world units along the unit
// direction from the camera centre). Exact per pixel (a ray-triangle intersection, not an
// interpolated z-buffer) and deterministic. Used for the ICT mesh's depth targets and silhouettes.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "icef/math/camera.h"
#include "icef/math/types.h"

namespace icef::face {

// [camera.width() * camera.height()] row-major: t of the first hit, +infinity where the ray meets
// no triangle. Triangles with a vertex at or behind the camera plane are skipped. hit_triangle,
// when given, gets the index into `triangles` of each pixel's first hit (-1: none).
std::vector<float> MeshDepthImage(std::span<const Vec3f> vertices,
                                  std::span<const std::array<uint32_t, 3>> triangles, const Camera& camera,
                                  std::vector<int32_t>* hit_triangle = nullptr);

}  // namespace icef::face
