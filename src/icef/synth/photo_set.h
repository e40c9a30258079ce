// Synthetic "photos with known truth" for testing a face tracker: one procedural subject (the
// dataset writer's identity, synthesize.h) photographed N times by a portrait pinhole camera at a
// random head pose, size and position in the frame, with a random expression, over a colourful
// procedural background (fractal-noise colour regions, warped stripes and blobs; a different one
// per photo), so segmentation is not trivial. Each photo carries its truth: the coverage mask, the
// camera (camera-to-head), the expression weights, the head pose and the 68 landmarks.
//
// Camera placement: the head frame is the world frame (+y up, the face looks down +z, head ~0.75
// tall). The head centre c = (0, (crown + chin) / 2, 0) (crown and chin heights from face::FaceGeometry)
// sits in the camera frame at (X, Y, -d) with its orientation cam_from_head = Rz(roll) Ry(yaw)
// Rx(-pitch): positive yaw turns the face towards the subject's left (image right), positive pitch
// lifts the chin, positive roll turns the head counter-clockwise in the image. d = f * H /
// (fraction * height) gives a head (crown to chin, H head units) of the drawn fraction of the image
// height; (X, Y) = d / f * (du, -dv) puts c's projection at the drawn offset (du, dv) pixels from
// the image centre. The intrinsics are a proper pinhole: fl_x = fl_y = focal_scale * max(w, h),
// principal point at the image centre. Every draw is a pure function of the options (same options,
// same pixels and bytes): photo i's pose, size and offset come from Rng(identity_seed,
// "synth.photos", 0, i), its expression from Rng(identity_seed, "synth.photo_expression", 0, i), its
// background from Rng(background seed, "synth.photo_background", 0, i).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/io/image.h"
#include "icef/io/json_util.h"
#include "icef/math/camera.h"
#include "icef/synth/ground_truth_renderer.h"
#include "icef/synth/identity.h"

namespace icef::synth {

struct PhotoSetOptions {
  // The subject: IdentityParams::FromSeed(identity_seed), as SynthOptions::identity_seed.
  uint64_t identity_seed = 1;
  // Render with the generic expression style instead of the identity's own (as SynthOptions).
  bool generic_style = false;
  // Number of photos N.
  int num_photos = 5;
  // Each photo's width and height in pixels (portrait by default).
  int width = 480;
  int height = 640;
  // Focal length in pixels divided by max(width, height) (1.4: a ~39 degree field across 640 px).
  double focal_scale = 1.4;
  // Head rotation relative to the camera, uniform within +-max (degrees; signs in the file header).
  double max_yaw_deg = 30.0;
  double max_pitch_deg = 15.0;
  double max_roll_deg = 8.0;
  // Head height (crown to chin) as a fraction of the image height, uniform in [min, max].
  double min_head_fraction = 0.35;
  double max_head_fraction = 0.6;
  // Head-centre offset from the image centre, uniform within +- this fraction of width (x) and
  // height (y). Validate() requires the largest head at the largest offset to fit in the image.
  double max_offset_fraction = 0.12;
  // Expression weights: 1-3 active expressions, each in [0.1, 1] * max_expression; photo 0 neutral.
  double max_expression = 0.8;
  // Seed of the backgrounds (0: derived from identity_seed).
  uint64_t background_seed = 0;
  // Ground-truth renderer settings (render.background is unused: the procedural background replaces it).
  RenderOptions render;

  Status Validate() const;
  std::string ToString() const;
  Json ToJson() const;
};

// One photo and its truth.
struct SynthPhoto {
  Image image;    // [height, width, 3] RGB: the head composited over the procedural background
  Image alpha;    // [height, width, 1]: the renderer's coverage in [0, 1] (the true head-and-neck mask)
  Camera camera;  // intrinsics + world_from_cam, world = the head frame (camera-to-head)
  std::vector<float> expression;                    // [face::kNumExpressions] true weights
  double yaw_deg = 0, pitch_deg = 0, roll_deg = 0;  // the drawn head pose (file header's convention)
  double head_fraction = 0;                         // the drawn head height / image height
  std::vector<Vec2f> landmarks_2d;                  // [68] pixels (+0.5 centres), ProjectLandmarks
  std::vector<bool> landmarks_visible;              // [68] in the image and not self-occluded
  std::vector<Vec3f> landmarks_3d;                  // [68] head frame, at the photo's expression

  std::string ToString() const;
};

// The subject of a photo set: IdentityParams::FromSeed(identity_seed), generic style when asked.
IdentityParams PhotoSetIdentity(const PhotoSetOptions& options);

// Everything drawn for one photo before rendering (cheap): the camera, pose, expression.
struct PhotoPlan {
  Camera camera;
  std::vector<float> expression;  // [face::kNumExpressions]
  double yaw_deg = 0, pitch_deg = 0, roll_deg = 0;
  double head_fraction = 0;
  Vec2d offset_px = Vec2d::Zero();  // head centre's projection minus the image centre (pixels)
};
// [N] plans; an error when the options are invalid or a camera would sit inside the head's box.
Result<std::vector<PhotoPlan>> PlanPhotoSet(const PhotoSetOptions& options);

// The procedural background of photo `index`: [height, width, 3] RGB, a pure function of
// (seed, index, width, height) (fractal-noise colour regions, warped stripes, blobs, a lighting
// gradient and grain in five random colours).
Image PhotoBackground(uint64_t seed, int index, int width, int height, const Executor& executor = Executor());

// Renders the N photos (the head with RenderGroundTruth, composited as alpha * rgb + (1 - alpha) *
// background). Deterministic whatever the executor's thread count.
Result<std::vector<SynthPhoto>> RenderPhotoSet(const PhotoSetOptions& options, const Executor& executor);

// Writes, atomically, under out_dir (created): photos/photo_NNN.png (RGB), truth/alpha_NNN.png
// (grey), truth/truth.json (kPhotoTruthFile: the options, then per photo its files, intrinsics,
// camera_to_head 4x4, head pose, expression by name, landmarks_2d, visibility and landmarks_3d; and
// the identity's true shape scales by name, "shape") and
// style.json (kStyleInfoFile, as SynthesizeDataset writes it).
inline constexpr char kPhotoTruthFile[] = "truth/truth.json";
Status WritePhotoSet(const PhotoSetOptions& options, const std::vector<SynthPhoto>& photos,
                     const std::filesystem::path& out_dir);
// The truth document WritePhotoSet writes (file names relative to out_dir).
Json PhotoSetTruthJson(const PhotoSetOptions& options, const std::vector<SynthPhoto>& photos);

}  // namespace icef::synth
