#include "icef/track/photo_track.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <system_error>

#include "icef/face/expression.h"
#include "icef/face/face_model.h"
#include "icef/face/shape_params.h"
#include "icef/io/atomic_file.h"
#include "icef/landmarks/face_mesh.h"

namespace icef::track {

namespace {

namespace fs = std::filesystem;

// Tier thresholds of the held-out photos (as `icef synth`'s defaults).
constexpr double kNearThreshold = 0.35;
constexpr double kFarThreshold = 0.8;

std::string Pad3(int i) {
  std::string s = std::to_string(i);
  return std::string(s.size() < 3 ? 3 - s.size() : 0, '0') + s;
}

double ExpressionDistance(const std::vector<float>& beta, const std::vector<Frame>& train) {
  double best = std::numeric_limits<double>::infinity();
  for (const Frame& f : train) {
    double s = 0;
    for (size_t i = 0; i < beta.size(); ++i) s += (beta[i] - f.expression[i]) * (beta[i] - f.expression[i]);
    best = std::min(best, std::sqrt(s));
  }
  return best;
}

Mat4d Inverse(const Mat4d& m) { return m.inverse(); }

struct Detected {
  Image photo;
  Result<FaceDetection> detection = Status::Error("not run");
};

// Reads and detects every photo (in parallel, one detector per thread, each photo into its slot).
// mesh: the face mesh's 68 landmarks (DetectFaceWithMesh) instead of dlib's.
Result<std::vector<Detected>> DetectAll(const std::vector<fs::path>& photos, const FaceLandmarkDetector& detector,
                                        const FaceMesh* mesh, const Executor& executor) {
  std::vector<Detected> out(photos.size());
  std::vector<Status> read_errors(photos.size());
  ParallelFor(executor, static_cast<int64_t>(photos.size()), [&](int64_t begin, int64_t end, int) {
    const FaceLandmarkDetector local = detector.Clone();
    for (int64_t i = begin; i < end; ++i) {
      Result<Image> image = ReadImage(photos[i]);
      if (!image.ok()) {
        read_errors[i] = image.status();
        continue;
      }
      const Image upright = Oriented(*image, ExifOrientation(photos[i]));
      out[i].photo = upright.HasAlpha() ? CompositeOver(upright, Vec3f::Ones()) : upright;
      out[i].detection = mesh ? DetectFaceWithMesh(local, *mesh, out[i].photo) : local.DetectFace(out[i].photo, /*averaged=*/true);
    }
  });
  for (size_t i = 0; i < photos.size(); ++i)
    if (!read_errors[i].ok())
      return Status::Error(photos[i].string() + ": cannot read the image: " + read_errors[i].message());
  return out;
}

Intrinsics PhotoIntrinsics(const fs::path& path, const Image& photo, const TrackOptions& options, FocalSource* source) {
  Intrinsics k;
  k.width = photo.width;
  k.height = photo.height;
  k.cx = 0.5 * photo.width;
  k.cy = 0.5 * photo.height;
  if (options.focal) {
    k.fl_x = *options.focal;
    *source = FocalSource::kFlag;
  } else if (const auto exif = ExifFocalPixels(path, photo.width, photo.height)) {
    k.fl_x = *exif;
    *source = FocalSource::kExif;
  } else {
    k.fl_x = DefaultFocalPixels(photo.width, photo.height);
    *source = FocalSource::kDefault;
  }
  k.fl_y = k.fl_x;
  return k;
}

// A tracked photo's crop around the fitted head, its camera and its foreground mask.
struct HeadCrop {
  CropBox box;
  Image rgb;      // the crop (RGB)
  Image outside;  // 1 where the crop leaves the photo
  Image mask;     // GrabCut's foreground
  Camera camera;  // the crop's camera (world = head frame)
};

HeadCrop CropHead(const face::FaceModel& model, const TrackedFrame& tracked, const TrackedPhoto& photo,
                  const TrackOptions& options, const PersonSegmenter* segmenter, const Executor& executor) {
  HeadCrop c;
  const Camera photo_camera(photo.photo_intrinsics, Inverse(tracked.cam_from_head));
  c.box = HeadCropBox(photo_camera, options.crop_margin);
  c.rgb = CropImage(photo.photo, c.box, options.resolution, &c.outside);
  c.camera = Camera(CropIntrinsics(photo.photo_intrinsics, c.box, options.resolution), Inverse(tracked.cam_from_head));
  const Image silhouette = HeadSilhouette(model, tracked.expression, c.camera, executor);
  Image person;
  if (segmenter) {
    Result<Image> p = segmenter->Run(c.rgb);
    ICEF_CHECK(p.ok(), p.status().message());  // the crop is always RGB
    person = std::move(*p);
  }
  c.mask = segmenter && options.segmentation == TrackOptions::Segmentation::kSelfieOnly
               ? PersonMask(person, c.outside)
               : HeadMask(c.rgb, silhouette, c.outside, person, options.mask);
  return c;
}

// max_points edge points of the photo's mask (evenly spaced along it), in the photo's pixels; with
// skin_only, those of them where skin lies just inside the edge (SkinEdges: the face's own outline,
// not hair over the cheeks, a hat or a collar).
std::vector<Vec2f> SilhouettePoints(const HeadCrop& c, const TrackedPhoto& photo, int resolution, int max_points,
                                    bool skin_only) {
  std::vector<Vec2f> points = MaskEdgePoints(c.mask, c.outside, max_points);
  if (skin_only) {
    const std::vector<Vec2f> lm = CropPoints(photo.detection.landmarks, c.box, resolution);
    const float iod = ((lm[36] + lm[39]) * 0.5f - (lm[42] + lm[45]) * 0.5f).norm();
    const std::vector<bool> keep = SkinEdges(c.rgb, c.mask, points, FitSkinModel(c.rgb, lm), 0.08 * iod);
    std::vector<Vec2f> skin;
    for (size_t i = 0; i < points.size(); ++i)
      if (keep[i]) skin.push_back(points[i]);
    points = std::move(skin);
  }
  const float scale = static_cast<float>(c.box.size / resolution);
  for (Vec2f& p : points) p = Vec2f(static_cast<float>(c.box.x0), static_cast<float>(c.box.y0)) + scale * p;
  return points;
}

// The dataset frame and image of one tracked photo.
void BuildFrame(const face::FaceModel& model, const TrackedFrame& tracked, const TrackOptions& options,
                const PersonSegmenter* segmenter, const Executor& executor, TrackedPhoto* photo, Frame* frame) {
  const HeadCrop c = CropHead(model, tracked, *photo, options, segmenter, executor);
  photo->crop = c.box;
  photo->image = Image(options.resolution, options.resolution, 4);
  for (int y = 0; y < options.resolution; ++y)
    for (int x = 0; x < options.resolution; ++x) {
      const Vec3f rgb = c.rgb.Rgb(x, y);
      for (int ch = 0; ch < 3; ++ch) photo->image.At(x, y, ch) = std::clamp(rgb[ch], 0.f, 1.f);
      photo->image.At(x, y, 3) = c.mask.At(x, y, 0);
    }
  const std::string split = photo->test ? "test" : "train";
  frame->file_path = "images/" + split + "_" + Pad3(photo->frame_index) + ".png";
  frame->camera = c.camera;
  frame->expression = tracked.expression;
  frame->landmarks_2d = CropPoints(photo->detection.landmarks, photo->crop, options.resolution);
  frame->landmarks_3d = std::vector<Vec3f>(tracked.landmarks_head.begin(), tracked.landmarks_head.end());
}

}  // namespace

const char* FocalSourceName(FocalSource source) {
  switch (source) {
    case FocalSource::kFlag: return "flag";
    case FocalSource::kExif: return "exif";
    case FocalSource::kDefault: return "default";
  }
  return "?";
}

Status TrackOptions::Validate() const {
  if (resolution < 32 || resolution > 4096) return Status::Error("resolution must be in [32, 4096]");
  if (focal && !(*focal > 0 && std::isfinite(*focal))) return Status::Error("focal must be a finite number > 0");
  if (num_test < 0) return Status::Error("the number of test photos must be >= 0");
  if (!(crop_margin >= 1 && crop_margin <= 3)) return Status::Error("crop_margin must be in [1, 3]");
  if (silhouette_points < 0) return Status::Error("silhouette_points must be >= 0");
  ICEF_RETURN_IF_ERROR(fit.Validate());
  return mask.Validate();
}

std::string TrackOptions::ToString() const {
  std::ostringstream os;
  os << "TrackOptions(resolution=" << resolution << ", focal=" << (focal ? std::to_string(*focal) : "auto")
     << ", num_test=" << num_test << ", skip_bad=" << skip_bad << ", crop_margin=" << crop_margin
     << ", silhouette_points=" << silhouette_points << ", segmentation=" << static_cast<int>(segmentation) << ", "
     << fit.ToString() << ", " << mask.ToString() << ")";
  return os.str();
}

Result<TrackResult> TrackPhotos(const std::vector<fs::path>& photos, const TrackOptions& options,
                                const FaceLandmarkDetector& detector, const Executor& executor,
                                const std::function<void(const std::string&)>& log) {
  ICEF_RETURN_IF_ERROR(options.Validate().WithContext("track options"));
  if (photos.empty()) return Status::Error("icef track: no photos given");
  std::optional<FaceMesh> mesh;
  if (options.fit.detector == LandmarkDetector::kMesh) {
    ICEF_ASSIGN_OR_RETURN(FaceMesh loaded, FaceMesh::Load());
    mesh = std::move(loaded);
  }
  std::optional<PersonSegmenter> segmenter;
  if (options.segmentation != TrackOptions::Segmentation::kNone) {
    ICEF_ASSIGN_OR_RETURN(PersonSegmenter loaded, PersonSegmenter::Load());
    segmenter = std::move(loaded);
  }
  ICEF_ASSIGN_OR_RETURN(std::vector<Detected> detected, DetectAll(photos, detector, mesh ? &*mesh : nullptr, executor));

  TrackResult result;
  for (size_t i = 0; i < photos.size(); ++i) {
    std::string why;
    if (!detected[i].detection.ok()) {
      why = "no face found";
    } else if (detected[i].detection->num_faces > 1) {
      why = std::to_string(detected[i].detection->num_faces) + " faces found; icef track needs exactly one per photo";
    }
    if (!why.empty()) {
      if (!options.skip_bad) return Status::Error(photos[i].string() + ": " + why + " (--skip-bad skips such photos)");
      result.skipped.push_back(photos[i].string() + ": " + why);
      if (log) log("skipped " + photos[i].string() + ": " + why);
      continue;
    }
    TrackedPhoto p;
    p.source = photos[i];
    p.photo = std::move(detected[i].photo);
    p.detection = std::move(*detected[i].detection);
    p.photo_intrinsics = PhotoIntrinsics(photos[i], p.photo, options, &p.focal_source);
    result.photos.push_back(std::move(p));
  }
  const int kept = static_cast<int>(result.photos.size());
  if (kept - options.num_test < 1)
    return Status::Error("icef track: needs at least one training photo with a face besides the --test ones, got " +
                         std::to_string(kept) + " photo" + (kept == 1 ? "" : "s") + " with a face and --test " +
                         std::to_string(options.num_test));

  std::vector<TrackFrame> frames;
  for (const TrackedPhoto& p : result.photos)
    frames.push_back(TrackFrame{p.detection.landmarks, p.photo_intrinsics, {}, {}, &p.photo});
  // The images join in the last fit only (the photometric refit starts from the landmarks').
  if (options.silhouette_points > 0)
    for (TrackFrame& f : frames) f.photo = nullptr;
  ICEF_ASSIGN_OR_RETURN(result.fit, FitTrack(frames, options.fit));
  if (log) log(result.fit.BriefReport());
  if (options.silhouette_points > 0) {
    // Refit with the silhouettes of the masks the landmark fit gives.
    const face::FaceModel first(result.fit.shape);
    for (int i = 0; i < kept; ++i) {
      // GrabCut alone: the refit reads the mask's edge where skin lies just inside it (SkinEdges),
      // which background GrabCut keeps rarely touches, and the fit proved sensitive to small changes
      // of that edge (docs/tracking.md); the segmentation cleans the dataset's alpha only.
      const HeadCrop c = CropHead(first, result.fit.frames[i], result.photos[i], options, nullptr, executor);
      frames[i].silhouette = SilhouettePoints(c, result.photos[i], options.resolution, options.silhouette_points,
                                              options.fit.silhouette_face_only);
      frames[i].photo = &result.photos[i].photo;
    }
    ICEF_ASSIGN_OR_RETURN(result.fit, FitTrack(frames, options.fit));
    if (log) log(result.fit.BriefReport() + " (refit with the masks' outlines)");
  }

  Dataset& d = result.dataset;
  d.expression_dim = face::kNumExpressions;
  d.expression_names = face::ExpressionNames();
  const face::FaceModel model(result.fit.shape);
  d.aabb = model.Bounds();
  d.aabb.min -= Vec3f::Constant(0.1f);
  d.aabb.max += Vec3f::Constant(0.1f);
  d.background = Vec3f::Ones();
  d.tier_thresholds = std::array<double, 2>{kNearThreshold, kFarThreshold};
  for (int i = 0; i < kept; ++i) {
    TrackedPhoto& p = result.photos[i];
    p.test = i >= kept - options.num_test;
    p.frame_index = p.test ? i - (kept - options.num_test) : i;
    Frame frame;
    BuildFrame(model, result.fit.frames[i], options, segmenter ? &*segmenter : nullptr, executor, &p, &frame);
    (p.test ? d.test : d.train).push_back(std::move(frame));
  }
  for (Frame& f : d.test) {
    f.delta = ExpressionDistance(f.expression, d.train);
    f.tier = *f.delta == 0 ? Tier::kObserved : *f.delta <= kNearThreshold ? Tier::kNear
                                              : *f.delta <= kFarThreshold ? Tier::kModerate
                                                                          : Tier::kFar;
  }
  return result;
}

Json TrackReportJson(const TrackResult& result) {
  Json photos = Json::array();
  for (size_t i = 0; i < result.photos.size(); ++i) {
    const TrackedPhoto& p = result.photos[i];
    const TrackedFrame& f = result.fit.frames[i];
    const Frame& frame = (p.test ? result.dataset.test : result.dataset.train)[p.frame_index];
    Json expression = Json::object();
    for (int e = 0; e < face::kNumExpressions; ++e) expression[face::kExpressionNames[e]] = JsonFloat(f.expression[e]);
    const Vec3d ypr = f.YawPitchRollDeg();
    const Vec3d t = f.cam_from_head.block<3, 1>(0, 3);
    photos.push_back(Json{{"photo", p.source.string()},
                          {"file_path", frame.file_path},
                          {"split", p.test ? "test" : "train"},
                          {"focal_px", p.photo_intrinsics.fl_x},
                          {"focal_source", FocalSourceName(p.focal_source)},
                          {"crop", {p.crop.x0, p.crop.y0, p.crop.size}},
                          {"landmark_rms_iod", f.rms_iod},
                          {"landmark_max_iod", f.max_iod},
                          {"landmarks_used", f.landmarks_used},
                          {"silhouette_rms_iod", f.silhouette_rms_iod},
                          {"silhouette_points_used", f.silhouette_used},
                          {"photometric_rms", f.photometric_rms},
                          {"photometric_points_used", f.photometric_used},
                          {"yaw_pitch_roll_deg", {ypr.x(), ypr.y(), ypr.z()}},
                          {"head_in_camera", {t.x(), t.y(), t.z()}},
                          {"expression", expression}});
  }
  Json shape = Json::object();
  const auto values = result.fit.shape.ToArray();
  for (int i = 0; i < face::ShapeParams::kCount; ++i) shape[face::kShapeParamNames[i]] = JsonFloat(values[i]);
  return Json{{"photos", photos},
              {"skipped", result.skipped},
              {"landmark_rms_iod", result.fit.rms_iod},
              {"photometric_refit", result.fit.photometric},
              {"silhouette_refit", result.fit.silhouettes},
              {"landmark_max_iod", result.fit.max_iod},
              {"iterations", result.fit.iterations},
              {"shape", shape}};
}

Status WriteTrackedDataset(const TrackResult& result, const fs::path& out_dir,
                           const std::vector<std::pair<std::string, Image>>& extra) {
  return CreateDirectoryAtomic(out_dir, [&](const fs::path& tmp) -> Status {
    std::error_code ec;
    fs::create_directories(tmp / "images", ec);
    fs::create_directories(tmp / "track", ec);
    Dataset d = result.dataset;
    d.root = tmp;
    for (const TrackedPhoto& p : result.photos)
      ICEF_RETURN_IF_ERROR(WritePng(tmp / (p.test ? d.test : d.train)[p.frame_index].file_path, p.image));
    ICEF_RETURN_IF_ERROR(SaveDataset(d));
    ICEF_RETURN_IF_ERROR(WriteFileAtomic(tmp / "track" / "report.json", FormatJson(TrackReportJson(result)) + "\n"));
    for (const auto& [name, image] : extra) ICEF_RETURN_IF_ERROR(WritePng(tmp / name, image));
    return Status::Ok();
  });
}

Result<std::vector<fs::path>> ExpandPhotoArguments(const std::vector<fs::path>& args) {
  std::vector<fs::path> out;
  for (const fs::path& a : args) {
    std::error_code ec;
    if (fs::is_directory(a, ec)) {
      std::vector<fs::path> files;
      for (const auto& entry : fs::directory_iterator(a, ec)) {
        std::string ext = entry.path().extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
        if (entry.is_regular_file() && (ext == ".png" || ext == ".jpg" || ext == ".jpeg")) files.push_back(entry.path());
      }
      if (ec) return Status::Error(a.string() + ": cannot list the directory: " + ec.message());
      std::sort(files.begin(), files.end());
      if (files.empty()) return Status::Error(a.string() + ": no .png/.jpg/.jpeg photos in the directory");
      out.insert(out.end(), files.begin(), files.end());
    } else if (fs::exists(a, ec)) {
      out.push_back(a);
    } else {
      return Status::Error(a.string() + ": no such file or directory");
    }
  }
  return out;
}

}  // namespace icef::track
