#include "icef/app/render_app.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "icef/app/face_outline.h"
#include "icef/data/dataset.h"
#include "icef/face/arkit_curves.h"
#include "icef/io/atomic_file.h"
#include "icef/io/gif_writer.h"
#include "icef/model/ict_prior.h"
#include "icef/model/render_image.h"
#include "icef/model/trained_model.h"
#include "icef/video/video_writer.h"

namespace icef {

namespace fs = std::filesystem;

Result<std::vector<float>> ParseVector(const std::string& text) {
  std::vector<float> v;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    char* end = nullptr;
    const float x = std::strtof(item.c_str(), &end);
    if (item.empty() || end == item.c_str() || *end != '\0' || !std::isfinite(x))
      return Status::Error("--beta: '" + item + "' is not a finite number");
    v.push_back(x);
  }
  return v;
}

Status ApplyNamedValue(const ModelSetup& setup, const std::string& assignment, std::vector<float>* beta) {
  const size_t eq = assignment.find('=');
  if (eq == std::string::npos)
    return Status::Error("'" + assignment + "': expected NAME=VALUE, e.g. jaw_open=0.8");
  const std::string name = assignment.substr(0, eq), value = assignment.substr(eq + 1);
  int index = setup.ExpressionIndex(name);
  if (index < 0) {  // "e3" or "3" address coefficients by index when the dataset has no names
    const std::string digits = (!name.empty() && name[0] == 'e') ? name.substr(1) : name;
    char* end = nullptr;
    const long i = std::strtol(digits.c_str(), &end, 10);
    if (!digits.empty() && *end == '\0' && i >= 0 && i < setup.expression_dim) index = static_cast<int>(i);
  }
  if (index < 0) {
    std::string names;
    for (const auto& n : setup.expression_names) names += (names.empty() ? "" : ", ") + n;
    return Status::Error(
        "unknown expression name '" + name + "' (the model's expression names: " +
        (names.empty() ? "none; use e0..e" + std::to_string(setup.expression_dim - 1) : names) + ")");
  }
  char* end = nullptr;
  const float x = std::strtof(value.c_str(), &end);
  if (value.empty() || *end != '\0' || !std::isfinite(x))
    return Status::Error("'" + assignment + "': value is not a finite number");
  (*beta)[index] = x;
  return Status::Ok();
}

// ICT-FaceKit, for an option that takes ARKit names (`what`: "--expression: ARKit names"); an error
// unless the model was trained in ICT-FaceKit's expression space.
Result<std::shared_ptr<const face::IctModel>> IctModelFor(const ModelSetup& setup, const std::string& what) {
  ICEF_ASSIGN_OR_RETURN(std::shared_ptr<const face::IctModel> ict, face::IctModel::LoadDefault());
  if (!IsIctExpressionSpace(*ict, setup.expression_names))
    return Status::Error(what +
                         " need a model trained on a dataset in ICT-FaceKit's expressions (icef track "
                         "--face-model ict); this model's are its own: use --set-expression NAME=VALUE");
  return ict;
}

// --expression: ARKit names, for a model in ICT-FaceKit's expression space.
Result<std::vector<float>> ArkitExpression(const ModelSetup& setup, const std::string& text) {
  ICEF_ASSIGN_OR_RETURN(const std::shared_ptr<const face::IctModel> ict,
                        IctModelFor(setup, "--expression: ARKit names"));
  Result<std::vector<float>> beta = face::ParseArkitExpression(*ict, text);
  if (!beta.ok()) return beta.status().WithContext("--expression");
  return beta;
}

// --expressions: the rows of a Live Link Face CSV, alone.
Result<std::vector<std::vector<float>>> ArkitCurveExpressions(const ModelSetup& setup,
                                                              const RenderAppOptions& o, std::ostream& out) {
  if (o.arkit_expression || o.beta || o.expression_frame || o.sweep || !o.named.empty())
    return Status::Error(
        "--expressions: the CSV gives every frame's expression; leave out --expression, --beta, "
        "--expression-frame, --set-expression and --sweep");
  ICEF_ASSIGN_OR_RETURN(const std::shared_ptr<const face::IctModel> ict,
                        IctModelFor(setup, "--expressions: ARKit curves"));
  ICEF_ASSIGN_OR_RETURN(face::ArkitCurves curves, face::ReadArkitCurves(*ict, *o.arkit_curves));
  out << "--expressions: " << curves.weights.size() << " frames from " << o.arkit_curves->string();
  if (!curves.ignored_columns.empty()) {
    out << "; columns with no blendshape of the model, ignored:";
    for (const std::string& c : curves.ignored_columns) out << " " << c;
  }
  if (!curves.missing_columns.empty()) {
    out << "; ARKit blendshapes with no column, held at 0:";
    for (const std::string& c : curves.missing_columns) out << " " << c;
  }
  out << "\n";
  return std::move(curves.weights);
}

std::vector<Camera> OrbitCameras(const ModelSetup& setup, int count, double yaw_deg, double pitch_deg,
                                 std::optional<int> resolution) {
  const Vec3d centre = setup.aabb.Center().cast<double>();
  Vec3d front = Vec3d::Zero();
  double distance = 0;
  for (const Camera& c : setup.training_cameras) {
    front += (c.Center() - centre).normalized();
    distance += (c.Center() - centre).norm();
  }
  distance /= std::max<size_t>(1, setup.training_cameras.size());
  front = front.norm() > 1e-9 ? front.normalized() : Vec3d::UnitZ();
  // Rotate about the world up axis (+Y, the NeRF convention's up) starting from `front`.
  Intrinsics k = setup.training_cameras.front().intrinsics();
  if (resolution) {
    const double s = double(*resolution) / k.height;
    k.width = std::max(1, int(std::lround(k.width * s)));
    k.height = *resolution;
    k.fl_x *= s, k.fl_y *= s, k.cx *= s, k.cy *= s;
  }
  std::vector<Camera> cams;
  for (int i = 0; i < count; ++i) {
    const double yaw = count > 1 ? (-yaw_deg + 2.0 * yaw_deg * i / (count - 1)) * M_PI / 180 : 0.0;
    const Eigen::AngleAxisd turn(yaw, Vec3d::UnitY());
    const Vec3d side = Vec3d::UnitY().cross(front).normalized();
    const Eigen::AngleAxisd tilt(-pitch_deg * M_PI / 180, side);
    const Vec3d dir = turn * (tilt * front);
    cams.push_back(Camera::LookAt(k, centre + distance * dir, centre, Vec3d::UnitY()));
  }
  return cams;
}

namespace {
Result<const Frame*> FindFrame(const Dataset& dataset, const std::string& spec, const char* option) {
  const size_t colon = spec.find(':');
  const std::string split = spec.substr(0, colon);
  const std::vector<Frame>* frames = split == "train"  ? &dataset.train
                                     : split == "test" ? &dataset.test
                                     : split == "val"  ? &dataset.val
                                                       : nullptr;
  char* end = nullptr;
  const std::string index_text = colon == std::string::npos ? "" : spec.substr(colon + 1);
  const long index = std::strtol(index_text.c_str(), &end, 10);
  if (!frames || index_text.empty() || *end != '\0')
    return Status::Error(std::string(option) + " '" + spec +
                         "': expected SPLIT:INDEX with SPLIT train, test or val");
  if (index < 0 || index >= static_cast<long>(frames->size()))
    return Status::Error(std::string(option) + " '" + spec + "': the " + split + " split has " +
                         std::to_string(frames->size()) + " frames");
  return &(*frames)[index];
}

Image ToRgb(const Image& scalar) {
  Image out(scalar.width, scalar.height, 3);
  for (size_t p = 0; p < scalar.pixels.size(); ++p)
    for (int c = 0; c < 3; ++c) out.pixels[3 * p + c] = scalar.pixels[p];
  return out;
}
}  // namespace

namespace {

// The dataset of --frame / --expression-frame (nullopt: none given), checked against the model.
Result<std::optional<Dataset>> LoadRenderDataset(const RenderAppOptions& o, const ModelSetup& setup) {
  std::optional<Dataset> dataset;
  if (o.dataset) {
    ICEF_ASSIGN_OR_RETURN(dataset, LoadDataset(*o.dataset));
    if (dataset->expression_dim != setup.expression_dim)
      return Status::Error(o.dataset->string() + ": expression_dim " +
                           std::to_string(dataset->expression_dim) + " does not match the model's " +
                           std::to_string(setup.expression_dim));
  }
  if ((o.frame || o.expression_frame) && !dataset)
    return Status::Error("--frame and --expression-frame need --dataset");
  if (o.frame && o.orbit > 0) return Status::Error("give either --frame or --orbit, not both");
  return dataset;
}

// The cameras: a dataset frame's, an orbit, or the default view.
Result<std::vector<Camera>> RenderCameras(const RenderAppOptions& o, const ModelSetup& setup,
                                          const std::optional<Dataset>& dataset) {
  std::vector<Camera> cameras;
  if (o.frame) {
    ICEF_ASSIGN_OR_RETURN(const Frame* f, FindFrame(*dataset, *o.frame, "--frame"));
    cameras.push_back(f->camera);
  } else if (o.orbit > 0) {
    cameras = OrbitCameras(setup, o.orbit, o.orbit_yaw, o.orbit_pitch, o.resolution);
  } else {
    cameras = OrbitCameras(setup, 1, 0, o.orbit_pitch, o.resolution);
  }
  return cameras;
}

// The expressions: the base (neutral, a dataset frame's, --beta, then the named values), or a sweep
// from it towards --sweep's target and beyond.
Result<std::vector<std::vector<float>>> RenderExpressions(const RenderAppOptions& o, const ModelSetup& setup,
                                                          const std::optional<Dataset>& dataset,
                                                          std::ostream& out) {
  if (o.arkit_curves) return ArkitCurveExpressions(setup, o, out);
  std::vector<float> base(setup.expression_dim, 0.f);
  if (o.expression_frame) {
    ICEF_ASSIGN_OR_RETURN(const Frame* f, FindFrame(*dataset, *o.expression_frame, "--expression-frame"));
    base = f->expression;
  }
  if (o.beta) {
    if (static_cast<int>(o.beta->size()) != setup.expression_dim)
      return Status::Error("--beta: expected " + std::to_string(setup.expression_dim) + " values, got " +
                           std::to_string(o.beta->size()));
    base = *o.beta;
  }
  if (o.arkit_expression) {
    ICEF_ASSIGN_OR_RETURN(base, ArkitExpression(setup, *o.arkit_expression));
  }
  for (const std::string& a : o.named)
    ICEF_RETURN_IF_ERROR(ApplyNamedValue(setup, a, &base).WithContext("--set-expression"));
  if (!o.sweep) return std::vector<std::vector<float>>{base};
  if (o.sweep_frames < 2) return Status::Error("--sweep-frames must be >= 2");
  if (!(o.sweep_beyond > 0) || !std::isfinite(o.sweep_beyond))
    return Status::Error("--sweep-beyond must be > 0");
  std::vector<float> target = base;
  ICEF_RETURN_IF_ERROR(ApplyNamedValue(setup, *o.sweep, &target).WithContext("--sweep"));
  std::vector<std::vector<float>> betas;
  for (int i = 0; i < o.sweep_frames; ++i) {
    const float t = static_cast<float>(o.sweep_beyond * i / (o.sweep_frames - 1));
    std::vector<float> b(setup.expression_dim);
    for (int k = 0; k < setup.expression_dim; ++k) b[k] = base[k] + t * (target[k] - base[k]);
    betas.push_back(b);
  }
  return betas;
}

// Every frame's render, and the sequence's depth and deformation ranges on the foreground (the
// colour scales of the depth and deformation images).
struct RenderedSequence {
  std::vector<RenderedImage> renders;
  float depth_lo = 1e30f, depth_hi = 0, deform_hi = 1e-6f;
};

RenderedSequence RenderSequence(const AvatarModel& model, const std::vector<Camera>& cameras,
                                const std::vector<std::vector<float>>& betas, const Executor& executor) {
  RenderedSequence seq;
  const size_t n = std::max(cameras.size(), betas.size());
  for (size_t i = 0; i < n; ++i) {
    const Camera& cam = cameras[std::min(i, cameras.size() - 1)];
    const std::vector<float>& beta = betas[std::min(i, betas.size() - 1)];
    seq.renders.push_back(RenderImage(model, cam, beta, model.setup().background, executor));
    const RenderedImage& r = seq.renders.back();
    for (size_t p = 0; p < r.depth.pixels.size(); ++p) {
      if (r.opacity.pixels[p] < 0.5f) continue;
      const float d = r.depth.pixels[p] / r.opacity.pixels[p];
      seq.depth_lo = std::min(seq.depth_lo, d), seq.depth_hi = std::max(seq.depth_hi, d);
      seq.deform_hi = std::max(seq.deform_hi, r.deformation.pixels[p]);
    }
  }
  if (!(seq.depth_hi > seq.depth_lo)) seq.depth_lo = 0, seq.depth_hi = 1;
  return seq;
}

// What the frames written so far add up to: their infos, frames.json entries and images (for the GIFs).
struct SequenceOutput {
  std::vector<RenderedFrameInfo> infos;
  Json frames = Json::array();
  std::vector<Image> colors, depths, masks, deforms;
};

// Writes frame i's PNGs (colour, depth, mask, deformation, and the fitted face model's outline on
// prior models), prints its line and adds it to `written`.
Status WriteRenderedFrame(const RenderAppOptions& o, const ModelSetup& setup, RenderedSequence& seq, size_t i,
                          const Camera& camera, const std::vector<float>& beta, SequenceOutput* written,
                          std::ostream& out) {
  RenderedImage& r = seq.renders[i];
  char name[32];
  std::snprintf(name, sizeof name, "%03zu", i);
  // Depth: expected depth / opacity on the foreground, shown over the sequence's range.
  Image depth(r.depth.width, r.depth.height, 1);
  for (size_t p = 0; p < depth.pixels.size(); ++p)
    depth.pixels[p] = r.opacity.pixels[p] > 0.05f ? r.depth.pixels[p] / r.opacity.pixels[p] : seq.depth_hi;
  Image depth_rgb = ColorizeScalar(depth, seq.depth_lo, seq.depth_hi);
  Image deform_rgb = ColorizeScalar(r.deformation, 0.f, seq.deform_hi);
  Image mask_rgb = ToRgb(r.mask);
  const fs::path color_path = o.out / (std::string("color_") + name + ".png");
  ICEF_RETURN_IF_ERROR(WritePng(color_path, r.color));
  ICEF_RETURN_IF_ERROR(WritePng(o.out / (std::string("depth_") + name + ".png"), depth_rgb));
  ICEF_RETURN_IF_ERROR(WritePng(o.out / (std::string("mask_") + name + ".png"), mask_rgb));
  ICEF_RETURN_IF_ERROR(WritePng(o.out / (std::string("deformation_") + name + ".png"), deform_rgb));
  if (setup.face_fit) {  // the fitted face model at this expression, over the render
    Image outline = r.color;
    DrawFaceOutline(&outline, camera, FittedLandmarks(*setup.face_fit, beta), Vec3f(1.f, 0.85f, 0.1f));
    ICEF_RETURN_IF_ERROR(WritePng(o.out / (std::string("fit_") + name + ".png"), outline));
  }
  written->infos.push_back({color_path.string(), beta, r.nearest});
  Json f;
  f["index"] = i;
  f["color"] = color_path.filename().string();
  f["expression"] = beta;
  f["delta"] = r.nearest.delta;
  f["kappa"] = r.nearest.kappa;
  f["nearest_training_frame"] = r.nearest.index;
  f["nearest_expression"] = setup.training_expressions[r.nearest.index];
  written->frames.push_back(f);
  out << "frame " << name << ": delta " << r.nearest.delta << ", kappa " << r.nearest.kappa
      << ", nearest observed expression: training frame " << r.nearest.index << " -> " << color_path.string()
      << "\n";
  written->colors.push_back(std::move(r.color));
  written->depths.push_back(std::move(depth_rgb));
  written->masks.push_back(std::move(mask_rgb));
  written->deforms.push_back(std::move(deform_rgb));
  return Status::Ok();
}

// frames.json, and a sequence's animated GIFs.
// The image padded by repeating its last column and row to even dimensions (H.264's yuv420p needs
// them); unchanged when both are even.
Image EvenSized(const Image& image) {
  const int w = image.width + image.width % 2, h = image.height + image.height % 2;
  if (w == image.width && h == image.height) return image;
  Image out(w, h, image.channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < image.channels; ++c)
        out.At(x, y, c) = image.At(std::min(x, image.width - 1), std::min(y, image.height - 1), c);
  return out;
}

Status WriteSequenceFiles(const RenderAppOptions& o, const std::string& method, const SequenceOutput& written,
                          std::ostream& out) {
  Json doc;
  doc["model"] = o.model.string();
  doc["method"] = method;
  doc["frames"] = written.frames;
  ICEF_RETURN_IF_ERROR(WriteFileAtomic(o.out / "frames.json", FormatJson(doc)));
  if (o.video) {
    VideoWriteOptions video;
    video.fps = o.fps;
    std::vector<Image> frames;
    for (const Image& color : written.colors) frames.push_back(EvenSized(color));
    ICEF_RETURN_IF_ERROR(WriteVideo(*o.video, frames, video));
    out << "video: " << o.video->string() << " (" << frames.size() << " frames at " << o.fps << " fps)\n";
  }
  if (written.colors.size() > 1) {
    ICEF_RETURN_IF_ERROR(WriteGif(o.out / "color.gif", written.colors, o.gif_delay_cs));
    ICEF_RETURN_IF_ERROR(WriteGif(o.out / "depth.gif", written.depths, o.gif_delay_cs));
    ICEF_RETURN_IF_ERROR(WriteGif(o.out / "mask.gif", written.masks, o.gif_delay_cs));
    ICEF_RETURN_IF_ERROR(WriteGif(o.out / "deformation.gif", written.deforms, o.gif_delay_cs));
    out << "animation: " << (o.out / "color.gif").string() << " (+ depth.gif, mask.gif, deformation.gif)\n";
  }
  return Status::Ok();
}

}  // namespace

Result<std::vector<RenderedFrameInfo>> RunRender(const RenderAppOptions& o, std::ostream& out) {
  if (o.video) {
    VideoWriteOptions video;
    video.fps = o.fps;
    if (Status valid = video.Validate(); !valid.ok()) return Status::Error("--fps: " + valid.message());
  }
  const Executor executor(o.threads);
  ICEF_ASSIGN_OR_RETURN(const TrainedModel loaded, LoadTrainedModel(o.model, executor, o.overrides));
  const AvatarModel& model = *loaded.model;
  const ModelSetup& setup = model.setup();
  ICEF_ASSIGN_OR_RETURN(const std::optional<Dataset> dataset, LoadRenderDataset(o, setup));
  ICEF_ASSIGN_OR_RETURN(const std::vector<Camera> cameras, RenderCameras(o, setup, dataset));
  ICEF_ASSIGN_OR_RETURN(const std::vector<std::vector<float>> betas,
                        RenderExpressions(o, setup, dataset, out));

  std::error_code ec;
  fs::create_directories(o.out, ec);
  if (!fs::is_directory(o.out)) return Status::Error(o.out.string() + ": cannot create the output directory");
  RenderedSequence seq = RenderSequence(model, cameras, betas, executor);
  SequenceOutput written;
  for (size_t i = 0; i < seq.renders.size(); ++i)
    ICEF_RETURN_IF_ERROR(WriteRenderedFrame(o, setup, seq, i, cameras[std::min(i, cameras.size() - 1)],
                                            betas[std::min(i, betas.size() - 1)], &written, out));
  ICEF_RETURN_IF_ERROR(WriteSequenceFiles(o, loaded.config.method, written, out));
  return std::move(written.infos);
}

}  // namespace icef
