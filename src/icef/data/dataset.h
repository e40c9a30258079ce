// The dataset format of docs/design.md §4: a directory with transforms_train.json,
// transforms_test.json and optionally transforms_val.json. Images are referenced by path and
// loaded on demand (LoadFrameImage), but their existence, readability and size are validated when
// the dataset is loaded.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/io/image.h"
#include "icef/math/camera.h"
#include "icef/math/ray.h"

namespace icef {

constexpr int kNumLandmarks = 68;  // iBUG-68 layout

// Extrapolation tiers of test frames (docs/design.md §6).
enum class Tier { kObserved, kNear, kModerate, kFar };
const char* TierName(Tier tier);
std::optional<Tier> ParseTier(const std::string& name);

struct Frame {
  std::string file_path;          // as written in the JSON, relative to the dataset directory
  Camera camera;                  // intrinsics (global or per-frame) + camera-to-world pose
  std::vector<float> expression;  // [expression_dim]
  std::optional<std::vector<Vec2f>> landmarks_2d;         // [68] pixels (image coordinates, +0.5 centres)
  std::optional<std::vector<bool>> landmarks_2d_visible;  // [68] false where occluded (optional)
  std::optional<std::vector<Vec3f>> landmarks_3d;         // [68] world frame
  std::optional<double> delta;                   // test frames: min_k ||beta - beta_k|| over training frames
  std::optional<Tier> tier;                      // test frames
  std::optional<std::string> neutral_file_path;  // test frames: same view at expression zero
  // Test frames: the 68 landmarks of that neutral image (2D pixels, 3D world frame; optional).
  std::optional<std::vector<Vec2f>> neutral_landmarks_2d;
  std::optional<std::vector<Vec3f>> neutral_landmarks_3d;
  // NerFace: the face's box [y0, y1, x0, x1] as fractions of the image height/width (optional).
  std::optional<std::array<float, 4>> bbox;
  std::string ToString() const;
};

struct Dataset {
  std::filesystem::path root;  // directory holding the transforms_*.json files
  Aabb aabb;                   // world frame
  int expression_dim = 0;
  std::vector<std::string> expression_names;        // [expression_dim], may be empty
  Vec3f background = Vec3f::Ones();                 // RGB in [0,1]
  std::optional<std::string> background_file_path;  // NerFace: a background image instead
  // Test-tier thresholds on delta: near = (0, t[0]], moderate = (t[0], t[1]], far > t[1].
  // JSON: "tier_thresholds": [t0, t1] (optional, written by `icef synth`).
  std::optional<std::array<double, 2>> tier_thresholds;
  std::vector<Frame> train;
  std::vector<Frame> test;
  std::vector<Frame> val;

  std::filesystem::path ImagePath(const Frame& frame) const { return root / frame.file_path; }
  std::string ToString() const;
};

// Loads and validates a dataset directory in our format; instant-ngp style `camera_angle_x` is
// accepted in place of fl_x. Errors name the file, the frame index and the field, e.g.
//   "data/transforms_train.json: frames[3].expression: expected an array of 12 numbers, got 11 values".
// Also loads NerFace datasets directly: "intrinsics" [fx, fy, cx, cy] (cx, cy as fractions of the
// image size when <= 1; focal lengths signed, as NerFace's real_to_nerf.py writes them: a negative
// one flips that image axis and every frame casts NerFace's rays, see dataset_load.cc), per-frame
// "expression" and "bbox", file paths without extension, and the background image bg/00050.png
// (or the first image in bg/) as background_file_path, its mean colour as `background`. Without
// "w"/"h" the size comes from each image; without "expression_dim" it is the length of the first
// training expression (0 when there is none); without "aabb" the box is [-1, 1]^3. A file_path
// without extension resolves to the existing .png/.jpg/.jpeg file and is stored with the extension.
// Keys we do not know are ignored.
Result<Dataset> LoadDataset(const std::filesystem::path& dir);

// Writes transforms_{train,test,val}.json (val only when non-empty) into dataset.root, each
// atomically. Images are not written here.
Status SaveDataset(const Dataset& dataset);

// The frame's image (RGB or RGBA, as stored). Errors name the file.
Result<Image> LoadFrameImage(const Dataset& dataset, const Frame& frame);

}  // namespace icef
