// `icef render`: images of a trained model for chosen cameras and expressions.
//
// Cameras: a dataset frame ("train:3", "test:0"; needs --dataset), an orbit (a turntable of N views
// around the mean training view, yaw within ±orbit_yaw degrees), or by default the first training
// camera. Expressions: a dataset frame's expression, an explicit vector, named values
// ("jaw_open=0.8", starting from neutral), or a sweep from neutral to a target and beyond. The
// number of output frames is the larger of the camera and expression counts (a single camera or
// expression is repeated). Per frame it writes color, depth, mask and deformation PNGs; sequences
// also get animated GIFs; frames.json lists delta, kappa and beta_n of every frame. Inference-only
// model keys (render.supersample, ...) may be overridden with "model.KEY=VALUE".
#pragma once

#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/io/json_util.h"
#include "icef/math/camera.h"
#include "icef/model/avatar_model.h"

namespace icef {

struct RenderAppOptions {
  std::filesystem::path model;                   // model directory or checkpoint file
  std::filesystem::path out;                     // output directory (created)
  std::optional<std::filesystem::path> dataset;  // for --frame / --expression-frame
  std::optional<std::string> frame;              // camera from a dataset frame: "split:index"
  int orbit = 0;                                 // > 0: turntable of this many views
  double orbit_yaw = 45;                         // turntable yaw half-range, degrees
  double orbit_pitch = 0;                        // turntable pitch, degrees
  std::optional<int> resolution;  // orbit/default camera: image height in pixels (width by aspect)
  std::optional<std::string> expression_frame;  // expression from a dataset frame: "split:index"
  std::optional<std::vector<float>> beta;       // explicit expression vector
  // ARKit-named weights "jawOpen=0.8,mouthSmileLeft=0.5" (models trained on an ICT-FaceKit dataset):
  // the whole expression, the weights not named 0 (face::ParseArkitExpression).
  std::optional<std::string> arkit_expression;
  // ARKit blendshape curves in Live Link Face's CSV layout (face/arkit_curves.h): one frame per row,
  // instead of the expressions above (same models as arkit_expression).
  std::optional<std::filesystem::path> arkit_curves;
  std::vector<std::string> named;              // "name=value" on top of neutral (or of beta / frame)
  std::optional<std::string> sweep;            // "name=value": neutral -> value * sweep_beyond
  int sweep_frames = 16;                       // frames of a sweep
  double sweep_beyond = 1.5;                   // the sweep ends at this multiple of the target
  int gif_delay_cs = 8;                        // GIF frame delay (1/100 s)
  std::optional<std::filesystem::path> video;  // also the colour frames as an MP4 (H.264) here
  double fps = 25;                             // its frame rate
  int threads = 0;                             // worker threads (0 = all cores)
  std::vector<std::string> overrides;  // "model.KEY=VALUE" of inference-only keys (model/trained_model.h)
};

struct RenderedFrameInfo {
  std::string color_path;
  std::vector<float> beta;
  NearestExpression nearest;
};

Result<std::vector<RenderedFrameInfo>> RunRender(const RenderAppOptions& options, std::ostream& out);

// Parsing helpers (exposed for tests). Errors name the option and the value.
// "0.1,0.2,..." -> values; RunRender checks the length against the model's expression_dim.
Result<std::vector<float>> ParseVector(const std::string& text);
Status ApplyNamedValue(const ModelSetup& setup, const std::string& assignment, std::vector<float>* beta);
// A turntable around the mean training view (looking at the aabb centre), `count` views with
// yaw in [-yaw, +yaw] degrees.
std::vector<Camera> OrbitCameras(const ModelSetup& setup, int count, double yaw_deg, double pitch_deg,
                                 std::optional<int> resolution);

}  // namespace icef
