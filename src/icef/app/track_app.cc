#include "icef/app/track_app.h"

#include <algorithm>
#include <cmath>
#include <iomanip>

#include "icef/app/curves_app.h"
#include "icef/app/detector_calibration.h"
#include "icef/app/face_outline.h"
#include "icef/core/parallel.h"
#include "icef/core/progress.h"
#include "icef/face/expression.h"
#include "icef/landmarks/face_landmark_detector.h"
#include "icef/video/video_reader.h"

namespace icef {

namespace {

constexpr int kOverlayHeight = 384;

void Dot(Image* image, const Vec2f& p, const Vec3f& colour) {
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int x = static_cast<int>(std::floor(p.x())) + dx, y = static_cast<int>(std::floor(p.y())) + dy;
      if (x < 0 || y < 0 || x >= image->width || y >= image->height) continue;
      for (int c = 0; c < 3; ++c) image->At(x, y, c) = colour[c];
    }
}

// RGBA over a grey checkerboard (RGB).
Image OverChecker(const Image& rgba) {
  Image out(rgba.width, rgba.height, 3);
  for (int y = 0; y < rgba.height; ++y)
    for (int x = 0; x < rgba.width; ++x) {
      const float a = rgba.At(x, y, 3);
      const float bg = ((x / 16 + y / 16) % 2) ? 0.55f : 0.8f;
      for (int c = 0; c < 3; ++c) out.At(x, y, c) = a * rgba.At(x, y, c) + (1 - a) * bg;
    }
  return out;
}

std::string ExpressionText(const std::vector<float>& beta, const std::vector<std::string>& names) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(2);
  bool any = false;
  for (size_t e = 0; e < beta.size() && e < names.size(); ++e)
    if (beta[e] >= 0.05f) os << (any ? " " : "") << names[e] << "=" << beta[e], any = true;
  return any ? os.str() : "neutral";
}

}  // namespace

Image TrackOverlay(const track::TrackResult& result, int photo_index) {
  const track::TrackedPhoto& p = result.photos[photo_index];
  const track::TrackedFrame& f = result.fit.frames[photo_index];
  const Vec3f green(0.1f, 0.95f, 0.2f), red(1.f, 0.15f, 0.1f), cyan(0.1f, 0.85f, 1.f);
  // The fitted landmarks as the fit saw them (dlib's convention), scaled to an image.
  auto fitted = [&](const std::vector<Vec2f>& points, double scale) {
    std::vector<std::optional<Vec2d>> uv;
    for (const Vec2f& q : points)
      uv.push_back(q.allFinite() ? std::optional<Vec2d>(q.cast<double>() * scale) : std::nullopt);
    return uv;
  };

  const int w =
      std::max(1, static_cast<int>(std::lround(double(p.photo.width) * kOverlayHeight / p.photo.height)));
  Image left = track::ResizeImage(p.photo, w, kOverlayHeight);
  const double s = double(kOverlayHeight) / p.photo.height;
  DrawFaceOutline2d(&left, fitted(f.projected, s), red);
  for (const Vec2f& q : f.silhouette_points) Dot(&left, (q.cast<double>() * s).cast<float>(), cyan);
  for (const Vec2f& l : p.detection.landmarks) Dot(&left, (l.cast<double>() * s).cast<float>(), green);

  Image right = track::ResizeImage(OverChecker(p.image), kOverlayHeight, kOverlayHeight);
  DrawFaceOutline2d(&right, fitted(track::CropPoints(f.projected, p.crop, kOverlayHeight), 1.0), red);

  Image out(left.width + right.width, kOverlayHeight, 3);
  for (int y = 0; y < kOverlayHeight; ++y) {
    for (int x = 0; x < left.width; ++x)
      for (int c = 0; c < 3; ++c) out.At(x, y, c) = left.Rgb(x, y)[c];
    for (int x = 0; x < right.width; ++x)
      for (int c = 0; c < 3; ++c) out.At(left.width + x, y, c) = right.At(x, y, c);
  }
  return out;
}

Image RetrackOverlay(const Image& frame, const Vec3f& background, std::span<const Vec2f> landmarks,
                     std::span<const Vec2f> fitted, std::span<const Vec2f> silhouette) {
  ICEF_CHECK(frame.channels == 3 || frame.channels == 4, "RetrackOverlay: 3 or 4 channels");
  Image rgb(frame.width, frame.height, 3);
  for (int y = 0; y < frame.height; ++y)
    for (int x = 0; x < frame.width; ++x) {
      const float a = frame.HasAlpha() ? frame.At(x, y, 3) : 1.f;
      for (int c = 0; c < 3; ++c) rgb.At(x, y, c) = a * frame.At(x, y, c) + (1 - a) * background[c];
    }
  const int w =
      std::max(1, static_cast<int>(std::lround(double(frame.width) * kOverlayHeight / frame.height)));
  Image out = track::ResizeImage(rgb, w, kOverlayHeight);
  const double s = double(kOverlayHeight) / frame.height;
  std::vector<std::optional<Vec2d>> uv;
  for (const Vec2f& q : fitted)
    uv.push_back(q.allFinite() ? std::optional<Vec2d>(q.cast<double>() * s) : std::nullopt);
  DrawFaceOutline2d(&out, uv, Vec3f(1.f, 0.15f, 0.1f));
  for (const Vec2f& q : silhouette) Dot(&out, (q.cast<double>() * s).cast<float>(), Vec3f(0.1f, 0.85f, 1.f));
  for (const Vec2f& l : landmarks)
    if (l.allFinite()) Dot(&out, (l.cast<double>() * s).cast<float>(), Vec3f(0.1f, 0.95f, 0.2f));
  return out;
}

std::vector<int> RetrackOverlayFrames(int n) { return track::SpreadFrames(n, kMaxRetrackOverlays); }

namespace {

// Every fitted frame of a --keep-cameras fit, in the fit's order (train, test, val, as
// RetrackResult::frame_names), with its overlay's name track/overlay_<split>_NNN.png.
std::vector<std::pair<std::string, const Frame*>> RetrackFrames(const track::RetrackResult& result) {
  const Dataset& d = result.dataset;
  std::vector<std::pair<std::string, const Frame*>> frames;
  for (const auto& [split, list] : {std::pair<const char*, const std::vector<Frame>*>{"train", &d.train},
                                    {"test", &d.test},
                                    {"val", &d.val}})
    for (size_t i = 0; i < list->size(); ++i) {
      char name[64];
      std::snprintf(name, sizeof(name), "track/overlay_%s_%03zu.png", split, i);
      frames.emplace_back(name, &(*list)[i]);
    }
  ICEF_CHECK(frames.size() == result.fit.frames.size(), "RetrackFrames: one fitted frame per dataset frame");
  return frames;
}

Status RunRetrack(const TrackAppOptions& options, std::ostream& out) {
  if (options.photos.size() != 1)
    return Status::Error("icef track --keep-cameras takes one dataset directory");
  ICEF_ASSIGN_OR_RETURN(const Dataset source, LoadDataset(options.photos[0]));
  track::RetrackOptions ro;
  ro.skip_bad = options.track.skip_bad;
  ro.landmarks = options.landmarks;
  ro.predictor_path = options.predictor;
  ro.fit = options.track.fit;
  ro.detector = options.track.fit.detector;
  ro.silhouette_points = options.track.silhouette_points;
  ro.fit_style = options.fit_style;
  ro.face_model = options.track.face_model;
  ro.ict_fit = options.track.ict_fit;
  out << "icef track --keep-cameras: " << options.photos[0].string() << " (" << source.train.size()
      << " training, " << source.test.size() << " test frames, expression_dim " << source.expression_dim
      << ")\n";
  ICEF_ASSIGN_OR_RETURN(const track::RetrackResult result,
                        track::RetrackDataset(source, ro, Executor(options.threads),
                                              [&](const std::string& line) { out << line << "\n"; }));
  // The overlays (RetrackOverlay) of RetrackOverlayFrames' frames.
  const auto frames = RetrackFrames(result);
  const std::vector<int> chosen = RetrackOverlayFrames(static_cast<int>(frames.size()));
  std::vector<std::pair<std::string, Image>> overlays;
  for (const int k : chosen) {
    const Frame& f = *frames[k].second;
    ICEF_ASSIGN_OR_RETURN(const Image image, LoadFrameImage(result.dataset, f));
    overlays.emplace_back(
        frames[k].first,
        RetrackOverlay(image, result.dataset.background,
                       f.landmarks_2d ? std::span<const Vec2f>(*f.landmarks_2d) : std::span<const Vec2f>(),
                       result.fit.frames[k].projected, result.fit.frames[k].silhouette_points));
  }
  for (size_t k = 0; k < result.fit.frames.size(); ++k) {
    if (result.fit.frames[k].rms_iod <= 0.05) continue;
    out << "warning: " << result.frame_names[k] << ": the face model fits its landmarks poorly (RMS "
        << result.fit.frames[k].rms_iod << " IOD > 0.05)";
    if (std::find(chosen.begin(), chosen.end(), static_cast<int>(k)) != chosen.end())
      out << "; check " << frames[k].first;
    out << "\n";
  }
  out << "head_from_world: " << result.fit.head_from_world->ToString() << "\n";
  ICEF_RETURN_IF_ERROR(track::WriteRetrackedDataset(result, options.out, overlays));
  out << "wrote " << options.out.string() << ": the same cameras and images, expressions in the face model's "
      << result.dataset.expression_dim << " weights; per-frame fit in "
      << (options.out / "track" / "report.json").string() << ", " << overlays.size() << " overlay"
      << (overlays.size() == 1 ? "" : "s") << " (track/overlay_<split>_NNN.png"
      << (overlays.size() < result.fit.frames.size() ? ", frames spread over the sequence" : "") << ")\n";
  return Status::Ok();
}

}  // namespace

Result<std::vector<track::TrackInput>> LoadTrackInputs(const TrackAppOptions& options, std::ostream& out) {
  std::vector<track::TrackInput> inputs;
  const bool any_video = std::any_of(options.photos.begin(), options.photos.end(),
                                     [](const std::filesystem::path& p) { return LooksLikeVideo(p); });
  if (!any_video) {
    if (options.every > 0 || options.max_frames > 0)
      return Status::Error("icef track: --every and --max-frames are for a video");
    ICEF_ASSIGN_OR_RETURN(const std::vector<std::filesystem::path> photos,
                          track::ExpandPhotoArguments(options.photos));
    out << "icef track: " << photos.size() << " photo" << (photos.size() == 1 ? "" : "s") << "\n";
    for (const auto& p : photos)
      inputs.push_back(track::TrackInput{p, p.string(), std::nullopt, std::nullopt});
    return inputs;
  }
  if (options.photos.size() != 1) return Status::Error("icef track: give one video, or photos, not both");
  const std::filesystem::path& video = options.photos[0];
  ICEF_ASSIGN_OR_RETURN(const VideoInfo info, ProbeVideo(video));
  VideoReadOptions ro;
  ro.every = options.every;
  ro.max_frames = options.max_frames > 0 ? options.max_frames : options.every > 0 ? 0 : kDefaultVideoFrames;
  ICEF_RETURN_IF_ERROR(ro.Validate().WithContext("icef track"));
  char head[160];
  std::snprintf(head, sizeof head, "icef track: %s, %dx%d, %.1f s at %.2f fps (%s)", video.string().c_str(),
                info.width, info.height, info.duration_s, info.fps, info.codec.c_str());
  out << head << "\n";
  ProgressBar bar("decode", std::max<int64_t>(info.frame_count_estimate, 1), out, options.interactive);
  ICEF_ASSIGN_OR_RETURN(std::vector<VideoFrame> frames,
                        ReadVideoFrames(video, ro, [&](int64_t decoded, int64_t) { bar.Update(decoded); }));
  bar.Finish(std::to_string(frames.size()) + " frames kept");
  for (VideoFrame& f : frames) {
    char name[256];
    std::snprintf(name, sizeof name, "%s@%.2fs", video.filename().string().c_str(), f.time_s);
    inputs.push_back(track::TrackInput{video, name, std::move(f.image), f.time_s});
  }
  return inputs;
}

Status RunTrack(const TrackAppOptions& options, std::ostream& out) {
  if (options.keep_cameras) return RunRetrack(options, out);
  ICEF_ASSIGN_OR_RETURN(std::vector<track::TrackInput> inputs, LoadTrackInputs(options, out));
  ICEF_ASSIGN_OR_RETURN(const FaceLandmarkDetector detector, FaceLandmarkDetector::Load(options.predictor));
  // A video's frames without exactly one face (turned away, blurred, cut) are skipped, saying so.
  track::TrackOptions track_options = options.track;
  if (!inputs.empty() && inputs[0].time_s) track_options.skip_bad = true;
  ICEF_ASSIGN_OR_RETURN(
      track::TrackResult result,
      track::TrackInputs(std::move(inputs), track_options, detector, Executor(options.threads),
                         [&](const std::string& line) { out << line << "\n"; }));
  std::vector<std::pair<std::string, Image>> overlays;
  for (size_t i = 0; i < result.photos.size(); ++i) {
    const track::TrackedPhoto& p = result.photos[i];
    const track::TrackedFrame& f = result.fit.frames[i];
    const Vec3d ypr = f.YawPitchRollDeg();
    out << std::fixed << std::setprecision(3) << "  " << p.name << " -> " << (p.test ? "test" : "train")
        << "[" << p.frame_index << "]: landmark RMS " << f.rms_iod << " IOD, yaw " << std::setprecision(1)
        << ypr.x() << " pitch " << ypr.y() << " roll " << ypr.z() << ", focal " << p.photo_intrinsics.fl_x
        << " px (" << track::FocalSourceName(p.focal_source) << "), "
        << ExpressionText(f.expression, result.dataset.expression_names) << "\n";
    out << std::setprecision(3);
    char name[64];
    std::snprintf(name, sizeof(name), "track/overlay_%03zu.png", i);
    if (f.rms_iod > 0.05)
      out << "  warning: " << p.name << ": the face model fits its landmarks poorly (RMS " << f.rms_iod
          << " IOD > 0.05); check " << name << "\n";
    overlays.emplace_back(name, TrackOverlay(result, static_cast<int>(i)));
  }
  out.unsetf(std::ios::fixed);
  ICEF_RETURN_IF_ERROR(track::WriteTrackedDataset(result, options.out, overlays));
  out << "wrote " << options.out.string() << ": " << result.dataset.train.size() << " training and "
      << result.dataset.test.size() << " test frames at " << options.track.resolution << "x"
      << options.track.resolution << "; overlays and report.json in " << (options.out / "track").string()
      << "\n";
  return Status::Ok();
}

namespace {

// The named choices of `icef track` (--segmentation, --detector, --silhouette-region, --landmarks,
// --generic-style) into `o`.
Status ApplyNamedTrackChoices(const TrackCommandOptions& c, TrackAppOptions* o) {
  using Segmentation = track::TrackOptions::Segmentation;
  const auto face_model = track::ParseTrackFaceModel(c.face_model);
  if (!face_model)
    return Status::Error("--face-model: expected procedural or ict, got \"" + c.face_model + "\"");
  o->track.face_model = *face_model;
  if (*face_model == track::TrackFaceModel::kIct &&
      (c.silhouette_points || c.photometric_weight || c.generic_style))
    return Status::Error(
        "--silhouette-points, --photometric-weight and --generic-style refine the procedural model's fit; "
        "ICT-FaceKit (--face-model ict) is fitted to the landmarks alone");
  if (c.segmentation != "selfie" && c.segmentation != "none" && c.segmentation != "selfie-only")
    return Status::Error("--segmentation: expected selfie, none or selfie-only, got \"" + c.segmentation +
                         "\"");
  o->track.segmentation = c.segmentation == "none"     ? Segmentation::kNone
                          : c.segmentation == "selfie" ? Segmentation::kSelfie
                                                       : Segmentation::kSelfieOnly;
  if (c.silhouette_region != "face" && c.silhouette_region != "head")
    return Status::Error("--silhouette-region: expected face or head, got \"" + c.silhouette_region + "\"");
  o->track.fit.silhouette_face_only = c.silhouette_region == "face";
  const auto landmarks = track::ParseRetrackLandmarks(c.landmarks);
  if (!landmarks)
    return Status::Error("--landmarks: expected detect, dlib or model, got \"" + c.landmarks + "\"");
  o->landmarks = *landmarks;
  o->fit_style = !c.generic_style;
  if (c.generic_style && !(o->keep_cameras && o->landmarks == track::RetrackLandmarks::kDatasetModel))
    return Status::Error(
        "--generic-style: only with --keep-cameras --landmarks model (the other landmarks are always "
        "read in the generic style)");
  if (c.detector != "mesh" && c.detector != "dlib")
    return Status::Error("--detector: expected mesh or dlib, got \"" + c.detector + "\"");
  o->track.fit.detector =
      c.detector == "mesh" ? track::LandmarkDetector::kMesh : track::LandmarkDetector::kDlib;
  return Status::Ok();
}

}  // namespace

const std::vector<uint64_t>& DetectorCalibrationSeeds() {
  static const std::vector<uint64_t> seeds = {101, 102, 103, 104, 105, 106, 107, 108, 109, 110, 111, 112};
  return seeds;
}

Result<TrackAppOptions> ResolveTrackOptions(const TrackCommandOptions& c) {
  TrackAppOptions o = c.app;
  ICEF_RETURN_IF_ERROR(ApplyNamedTrackChoices(c, &o));
  // The options not given: the mode's defaults (a dataset's frames: RetrackOptions').
  const track::RetrackOptions retrack;
  if (c.photometric_weight) {
    o.track.fit.photometric_weight = *c.photometric_weight;
  } else if (o.keep_cameras) {
    o.track.fit.photometric_weight = retrack.fit.photometric_weight;
  }
  if (c.silhouette_points) {
    o.track.silhouette_points = *c.silhouette_points;
  } else if (o.keep_cameras) {
    o.track.silhouette_points = retrack.silhouette_points;  // the source's default
  }
  if (c.landmark_sigma) {
    o.track.fit.landmark_sigma_iod = *c.landmark_sigma;
  } else if (o.keep_cameras) {
    o.track.fit.landmark_sigma_iod = retrack.fit.landmark_sigma_iod;
  }
  if (c.focal) o.track.focal = *c.focal;
  return o;
}

Status RunTrackCommand(const TrackCommandOptions& c, std::ostream& out, std::ostream& log) {
  ICEF_ASSIGN_OR_RETURN(const TrackAppOptions options, ResolveTrackOptions(c));
  if (c.calibrate_detector) {
    const bool mesh = options.track.fit.detector == track::LandmarkDetector::kMesh;
    const Executor executor(options.threads);
    ICEF_ASSIGN_OR_RETURN(const DetectorCalibration calibration,
                          CalibrateDetector(DetectorCalibrationSeeds(), executor, &log, mesh));
    PrintDetectorTable(calibration, out);
    return Status::Ok();
  }
  if (options.photos.empty())
    return Status::Error("icef track: give the photos (or a dataset with --keep-cameras)");
  if (!c.curves.empty()) return RunTrackCurves(options, c.curves, out);
  if (options.out.empty()) return Status::Error("icef track: --out DATASET is required");
  return RunTrack(options, out);
}

}  // namespace icef
