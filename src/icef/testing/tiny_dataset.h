// Tiny on-disk datasets for tests of every module: a few small PNGs and transforms_*.json,
// written in a second or less. Test-only: failures throw InternalError via ICEF_CHECK.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "icef/data/dataset.h"
#include "icef/io/json_util.h"

namespace icef::testing {

struct TinyDatasetOptions {
  int num_train = 3;          // training frames (K)
  int num_test = 2;           // test frames; they carry delta and tier
  int num_val = 0;            // validation frames
  int width = 8;              // image width in pixels
  int height = 6;             // image height in pixels
  int expression_dim = 4;     // B; expression_names are "e0", "e1", ...
  bool landmarks_2d = true;   // 68 projected landmarks on every frame
  bool landmarks_3d = false;  // 68 world-frame landmarks on every frame
  bool alpha = false;         // RGBA images instead of RGB
  uint64_t seed = 1;          // every random value derives from it
  Status Validate() const;
  std::string ToString() const;
};

// Writes a valid dataset into `dir` (created if missing): images/<split>_NNN.png and the
// transforms files via SaveDataset. Cameras look at the origin from radius 3; test frame 0 reuses
// training expression 0 (tier "observed", delta 0), the others get random expressions with their
// delta and tier (thresholds [0.5, 1.0]). Returns the dataset as written (root = dir).
Dataset WriteTinyDataset(const std::filesystem::path& dir, const TinyDatasetOptions& options = {});

struct TinyNerfaceOptions {
  int num_train = 3;        // frames in transforms_train.json
  int num_val = 1;          // frames in transforms_val.json
  int num_test = 1;         // frames in transforms_test.json
  int size = 8;             // square image size in pixels
  int expression_dim = 76;  // NerFace's usual expression length
  // Focal lengths as NerFace's real_to_nerf.py writes them: the file's fx, fy negative, and train
  // frames 1 and 2 with their own "intrinsics", one focal length negative each (needs num_train >= 3).
  bool signed_focals = false;
  uint64_t seed = 2;  // every random value derives from it
  Status Validate() const;
  std::string ToString() const;
};

// What WriteTinyNerfaceDataset wrote, for tests to compare against.
struct TinyNerfaceInfo {
  double camera_angle_x = 0;
  std::array<double, 4> intrinsics{};  // the file's [fx, fy, cx, cy], cx/cy as fractions
  Vec3f background_mean = Vec3f::Zero();
};

// Writes a NerFace-layout dataset (github.com/gafniguy/4D-Facial-Avatars) into `dir`:
// transforms_{train,val,test}.json with camera_angle_x, a global "intrinsics" [fx, fy, cx, cy],
// per-frame "expression" and "bbox", file paths "./train/f_0000" without extension, images
// train/f_0000.png ..., and the background image bg/00050.png. No w, h, aabb or expression_dim.
TinyNerfaceInfo WriteTinyNerfaceDataset(const std::filesystem::path& dir,
                                        const TinyNerfaceOptions& options = {});

// A ray in double precision: origin and unit direction, world frame.
struct RayD {
  Vec3d origin;
  Vec3d direction;
};

// NerFace's ray through integer pixel (column i, row j) of frame `index` of a NerFace transforms
// file `transforms` whose images are w x h, computed from the JSON as NerFace's get_ray_bundle does:
// origin the translation of transform_matrix (c2w), direction its rotation times
// ((i - w cx) / fx, -(j - h cy) / fy, -1), normalised, with the frame's "intrinsics"
// [fx, fy, cx, cy] (else the file's) taken as they are: signed focal lengths, cx, cy as fractions.
// The reference that tests hold our cameras to.
RayD NerfaceRay(const Json& transforms, int index, int w, int h, int i, int j);

// A fresh, empty directory under the system temp directory, named after the running test.
std::filesystem::path MakeTempDir(const std::string& name);

}  // namespace icef::testing
