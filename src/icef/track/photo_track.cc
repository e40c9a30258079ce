#include "icef/track/photo_track.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <system_error>

#include "icef/core/enum_table.h"
#include "icef/data/frame_coverage.h"
#include "icef/face/expression.h"
#include "icef/face/face_model.h"
#include "icef/face/shape_params.h"
#include "icef/io/atomic_file.h"
#include "icef/landmarks/face_mesh.h"
#include "icef/track/dataset_retrack.h"
#include "icef/track/ict_track.h"

namespace icef::track {

namespace {

namespace fs = std::filesystem;

// An ICT-tracked dataset's aabb around the neutral head: room for hair (world units, ~5 cm).
constexpr float kIctAabbMargin = 0.13f;

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

// Reads (where not decoded already) and detects every input (in parallel, one detector per thread,
// each input into its slot). mesh: the face mesh's 68 landmarks (DetectFaceWithMesh) instead of dlib's.
Result<std::vector<Detected>> DetectAll(std::vector<TrackInput>& inputs, const FaceLandmarkDetector& detector,
                                        const FaceMesh* mesh, const Executor& executor) {
  std::vector<Detected> out(inputs.size());
  std::vector<Status> read_errors(inputs.size());
  ParallelFor(executor, static_cast<int64_t>(inputs.size()), [&](int64_t begin, int64_t end, int) {
    const FaceLandmarkDetector local = detector.Clone();
    for (int64_t i = begin; i < end; ++i) {
      if (inputs[i].image) {
        out[i].photo = std::move(*inputs[i].image);
        inputs[i].image.reset();
      } else {
        Result<Image> image = ReadImage(inputs[i].source);
        if (!image.ok()) {
          read_errors[i] = image.status();
          continue;
        }
        out[i].photo = Oriented(*image, ExifOrientation(inputs[i].source));
      }
      if (out[i].photo.HasAlpha()) out[i].photo = CompositeOver(out[i].photo, Vec3f::Ones());
      out[i].detection = DetectTrackLandmarks(local, mesh, out[i].photo);
    }
  });
  for (size_t i = 0; i < inputs.size(); ++i)
    if (!read_errors[i].ok())
      return Status::Error(inputs[i].source.string() +
                           ": cannot read the image: " + read_errors[i].message());
  return out;
}

// EXIF is read from photo files only (exif_path empty: a video frame).
Intrinsics PhotoIntrinsics(const fs::path& exif_path, const Image& photo, const TrackOptions& options,
                           FocalSource* source) {
  Intrinsics k;
  k.width = photo.width;
  k.height = photo.height;
  k.cx = 0.5 * photo.width;
  k.cy = 0.5 * photo.height;
  if (options.focal) {
    k.fl_x = *options.focal;
    *source = FocalSource::kFlag;
  } else if (const auto exif =
                 exif_path.empty() ? std::nullopt : ExifFocalPixels(exif_path, photo.width, photo.height)) {
    k.fl_x = *exif;
    *source = FocalSource::kExif;
  } else {
    k.fl_x = DefaultFocalPixels(photo.width, photo.height);
    *source = FocalSource::kDefault;
  }
  k.fl_y = k.fl_x;
  return k;
}

// The fitted head's silhouette in a camera (world frame: the dataset's): what the mask starts from.
using SilhouetteFn = std::function<Image(const TrackedFrame&, const Camera&)>;

// A tracked photo's crop around the fitted head, its camera and its foreground mask.
struct HeadCrop {
  CropBox box;
  Image rgb;      // the crop (RGB)
  Image outside;  // 1 where the crop leaves the photo
  Image mask;     // GrabCut's foreground
  Camera camera;  // the crop's camera (world = head frame)
};

HeadCrop CropHead(const SilhouetteFn& silhouette_of, const TrackedFrame& tracked, const TrackedPhoto& photo,
                  const TrackOptions& options, const PersonSegmenter* segmenter) {
  HeadCrop c;
  const Camera photo_camera(photo.photo_intrinsics, Inverse(tracked.cam_from_head));
  c.box = HeadCropBox(photo_camera, options.crop_margin);
  c.rgb = CropImage(photo.photo, c.box, options.resolution, &c.outside);
  c.camera = Camera(CropIntrinsics(photo.photo_intrinsics, c.box, options.resolution),
                    Inverse(tracked.cam_from_head));
  const Image silhouette = silhouette_of(tracked, c.camera);
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
std::vector<Vec2f> SilhouettePoints(const HeadCrop& c, const TrackedPhoto& photo, int resolution,
                                    int max_points, bool skin_only) {
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
void BuildFrame(const SilhouetteFn& silhouette_of, const TrackedFrame& tracked, const TrackOptions& options,
                const PersonSegmenter* segmenter, TrackedPhoto* photo, Frame* frame) {
  const HeadCrop c = CropHead(silhouette_of, tracked, *photo, options, segmenter);
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

// Splits the tracked photos (TrackOptions::num_test, num_train): sets test and frame_index, and
// drops the photos that are neither (with their fitted frames). Training frames keep input order.
void AssignSplits(const TrackOptions& options, const std::vector<std::string>& expression_names,
                  TrackResult* result) {
  const int n = static_cast<int>(result->photos.size());
  std::vector<int> role(n, 0);  // 0: left out, 1: train, 2: test
  if (options.num_train <= 0) {
    for (int i = 0; i < n; ++i) role[i] = i >= n - options.num_test ? 2 : 1;
  } else {
    std::vector<double> sharpness(n);
    for (int i = 0; i < n; ++i) sharpness[i] = result->photos[i].sharpness;
    std::vector<double> sorted = sharpness;
    std::sort(sorted.begin(), sorted.end());
    const double median = sorted[n / 2];
    std::vector<CoverageCandidate> candidates(n);
    for (int i = 0; i < n; ++i) {
      const TrackedFrame& f = result->fit.frames[i];
      Frame frame;  // the camera and expression CandidateOfFrame reads
      frame.camera = Camera(result->photos[i].photo_intrinsics, Inverse(f.cam_from_head));
      frame.expression = f.expression;
      candidates[i] = CandidateOfFrame(frame, expression_names);
      candidates[i].sharpness = median > 0 ? sharpness[i] / median : 1;
    }
    CoverageOptions co;
    co.allow_blink = options.allow_blink;
    for (const int i : ChooseCoverageFrames(candidates, options.num_train, co)) role[i] = 1;
    std::vector<int> rest;
    for (int i = 0; i < n; ++i)
      if (role[i] == 0) rest.push_back(i);
    const int num_test = options.num_test > 0 ? options.num_test : static_cast<int>(rest.size());
    for (const int r : SpreadFrames(static_cast<int>(rest.size()), num_test)) role[rest[r]] = 2;
  }
  std::vector<TrackedPhoto> photos;
  std::vector<TrackedFrame> frames;
  int num_train = 0, num_test = 0;
  for (int i = 0; i < n; ++i) {
    if (role[i] == 0) continue;
    TrackedPhoto& p = result->photos[i];
    p.test = role[i] == 2;
    p.frame_index = p.test ? num_test++ : num_train++;
    photos.push_back(std::move(p));
    frames.push_back(std::move(result->fit.frames[i]));
  }
  result->photos = std::move(photos);
  result->fit.frames = std::move(frames);
}

// The procedural model's fit: landmarks, then (with silhouette_points) the outlines of the masks the
// landmark fit gives, with the photometric refit in the last fit.
Status FitProcedural(const TrackOptions& options, const Executor& executor, TrackResult* result,
                     const std::function<void(const std::string&)>& log) {
  std::vector<TrackFrame> frames;
  for (const TrackedPhoto& p : result->photos)
    frames.push_back(TrackFrame{p.detection.landmarks, p.photo_intrinsics, {}, {}, &p.photo});
  // The images join in the last fit only (the photometric refit starts from the landmarks').
  if (options.silhouette_points > 0)
    for (TrackFrame& f : frames) f.photo = nullptr;
  ICEF_ASSIGN_OR_RETURN(result->fit, FitTrack(frames, options.fit));
  if (log) log(result->fit.BriefReport());
  if (options.silhouette_points <= 0) return Status::Ok();
  // Refit with the silhouettes of the masks the landmark fit gives.
  const face::FaceModel first(result->fit.shape);
  const SilhouetteFn silhouette_of = [&](const TrackedFrame& f, const Camera& camera) {
    return HeadSilhouette(first, f.expression, camera, executor);
  };
  for (size_t i = 0; i < frames.size(); ++i) {
    // GrabCut alone: the refit reads the mask's edge where skin lies just inside it (SkinEdges),
    // which background GrabCut keeps rarely touches, and the fit proved sensitive to small changes
    // of that edge (docs/tracking.md); the segmentation cleans the dataset's alpha only.
    const HeadCrop c = CropHead(silhouette_of, result->fit.frames[i], result->photos[i], options, nullptr);
    frames[i].silhouette = SilhouettePoints(c, result->photos[i], options.resolution,
                                            options.silhouette_points, options.fit.silhouette_face_only);
    frames[i].photo = &result->photos[i].photo;
  }
  ICEF_ASSIGN_OR_RETURN(result->fit, FitTrack(frames, options.fit));
  if (log) log(result->fit.BriefReport() + " (refit with the masks' outlines)");
  return Status::Ok();
}

// ICT's fit: landmarks only (track/ict_track.h).
Status FitIct(const face::IctModel& model, const TrackOptions& options, TrackResult* result,
              const std::function<void(const std::string&)>& log) {
  std::vector<TrackFrame> frames;
  for (const TrackedPhoto& p : result->photos)
    frames.push_back(TrackFrame{p.detection.landmarks, p.photo_intrinsics, {}, {}, nullptr});
  ICEF_ASSIGN_OR_RETURN(result->fit, FitIctTrack(model, frames, options.ict_fit));
  std::ostringstream os;
  os << "ICT-FaceKit fit to the landmarks of " << frames.size() << " photo" << (frames.size() == 1 ? "" : "s")
     << ": RMS " << result->fit.rms_iod << " IOD (max " << result->fit.max_iod << "), "
     << result->fit.iterations << " iterations";
  if (log) log(os.str());
  return Status::Ok();
}

constexpr std::array<EnumEntry<TrackFaceModel>, 2> kTrackFaceModelNames = {
    {{TrackFaceModel::kProcedural, "procedural"}, {TrackFaceModel::kIct, "ict"}}};

}  // namespace

const char* TrackFaceModelName(TrackFaceModel model) { return EnumName(kTrackFaceModelNames, model); }

std::optional<TrackFaceModel> ParseTrackFaceModel(const std::string& name) {
  return ParseEnum(kTrackFaceModelNames, name);
}

Result<FaceDetection> DetectTrackLandmarks(const FaceLandmarkDetector& detector, const FaceMesh* mesh,
                                           const Image& photo) {
  return mesh ? DetectFaceWithMesh(detector, *mesh, photo) : detector.DetectFace(photo, /*averaged=*/true);
}

double FaceSharpness(const Image& photo, std::span<const Vec2f> landmarks) {
  if (landmarks.empty()) return 0;
  Vec2f lo = landmarks[0], hi = landmarks[0];
  for (const Vec2f& p : landmarks) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const int x0 = std::clamp(static_cast<int>(std::floor(lo.x())), 0, photo.width - 1);
  const int y0 = std::clamp(static_cast<int>(std::floor(lo.y())), 0, photo.height - 1);
  const int x1 = std::clamp(static_cast<int>(std::ceil(hi.x())), x0 + 1, photo.width);
  const int y1 = std::clamp(static_cast<int>(std::ceil(hi.y())), y0 + 1, photo.height);
  cv::Mat grey(y1 - y0, x1 - x0, CV_32F);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const Vec3f c = photo.Rgb(x, y);
      grey.at<float>(y - y0, x - x0) = 0.299f * c[0] + 0.587f * c[1] + 0.114f * c[2];
    }
  cv::Mat small, laplacian;
  cv::resize(grey, small, cv::Size(96, 96), 0, 0, cv::INTER_AREA);
  cv::Laplacian(small, laplacian, CV_32F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(laplacian, mean, stddev);
  return stddev[0] * stddev[0];
}

const char* FocalSourceName(FocalSource source) {
  switch (source) {
    case FocalSource::kFlag:
      return "flag";
    case FocalSource::kExif:
      return "exif";
    case FocalSource::kDefault:
      return "default";
  }
  return "?";
}

Status TrackOptions::Validate() const {
  if (resolution < 32 || resolution > 4096) return Status::Error("resolution must be in [32, 4096]");
  if (num_train < 0) return Status::Error("the number of training frames must be >= 0");
  if (focal && !(*focal > 0 && std::isfinite(*focal)))
    return Status::Error("focal must be a finite number > 0");
  if (num_test < 0) return Status::Error("the number of test photos must be >= 0");
  if (!(crop_margin >= 1 && crop_margin <= 3)) return Status::Error("crop_margin must be in [1, 3]");
  if (silhouette_points < 0) return Status::Error("silhouette_points must be >= 0");
  ICEF_RETURN_IF_ERROR(fit.Validate());
  ICEF_RETURN_IF_ERROR(ict_fit.Validate());
  return mask.Validate();
}

std::string TrackOptions::ToString() const {
  std::ostringstream os;
  os << "TrackOptions(";
  // The procedural model's options read as before ICT joined (the real bench's cached tracks stay valid).
  if (face_model != TrackFaceModel::kProcedural)
    os << "face_model=" << TrackFaceModelName(face_model) << ", " << ict_fit.ToString() << ", ";
  os << "resolution=" << resolution << ", focal=" << (focal ? std::to_string(*focal) : "auto")
     << ", num_test=" << num_test << ", num_train=" << num_train << ", allow_blink=" << allow_blink
     << ", skip_bad=" << skip_bad << ", crop_margin=" << crop_margin
     << ", silhouette_points=" << silhouette_points << ", segmentation=" << static_cast<int>(segmentation)
     << ", " << fit.ToString() << ", " << mask.ToString() << ")";
  return os.str();
}

Result<TrackResult> TrackPhotos(const std::vector<fs::path>& photos, const TrackOptions& options,
                                const FaceLandmarkDetector& detector, const Executor& executor,
                                const std::function<void(const std::string&)>& log) {
  std::vector<TrackInput> inputs;
  for (const fs::path& p : photos) inputs.push_back(TrackInput{p, p.string(), std::nullopt, std::nullopt});
  return TrackInputs(std::move(inputs), options, detector, executor, log);
}

Result<TrackResult> TrackInputs(std::vector<TrackInput> inputs, const TrackOptions& options,
                                const FaceLandmarkDetector& detector, const Executor& executor,
                                const std::function<void(const std::string&)>& log) {
  ICEF_RETURN_IF_ERROR(options.Validate().WithContext("track options"));
  if (inputs.empty()) return Status::Error("icef track: no photos given");
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
  // Decoded frames carry no EXIF; photo files are read (and their EXIF) by name.
  std::vector<bool> decoded(inputs.size());
  for (size_t i = 0; i < inputs.size(); ++i) decoded[i] = inputs[i].image.has_value();
  ICEF_ASSIGN_OR_RETURN(std::vector<Detected> detected,
                        DetectAll(inputs, detector, mesh ? &*mesh : nullptr, executor));

  TrackResult result;
  for (size_t i = 0; i < inputs.size(); ++i) {
    std::string why;
    if (!detected[i].detection.ok()) {
      why = "no face found";
    } else if (detected[i].detection->num_faces > 1) {
      why = std::to_string(detected[i].detection->num_faces) +
            " faces found; icef track needs exactly one per photo";
    }
    if (!why.empty()) {
      const std::string label = inputs[i].Label();
      if (!options.skip_bad) return Status::Error(label + ": " + why + " (--skip-bad skips such photos)");
      result.skipped.push_back(label + ": " + why);
      if (log) log("skipped " + label + ": " + why);
      continue;
    }
    TrackedPhoto p;
    p.source = inputs[i].source;
    p.name = inputs[i].Label();
    p.time_s = inputs[i].time_s;
    p.photo = std::move(detected[i].photo);
    p.detection = std::move(*detected[i].detection);
    p.sharpness = FaceSharpness(p.photo, p.detection.landmarks);
    p.photo_intrinsics =
        PhotoIntrinsics(decoded[i] ? fs::path() : inputs[i].source, p.photo, options, &p.focal_source);
    result.photos.push_back(std::move(p));
  }
  const int kept = static_cast<int>(result.photos.size());
  if (options.num_train <= 0 && kept - options.num_test < 1)
    return Status::Error(
        "icef track: needs at least one training photo with a face besides the --test ones, got " +
        std::to_string(kept) + " photo" + (kept == 1 ? "" : "s") + " with a face and --test " +
        std::to_string(options.num_test));
  if (options.num_train > 0 && kept < options.num_train + std::max(options.num_test, 1))
    return Status::Error("icef track: --frames " + std::to_string(options.num_train) + " --test " +
                         std::to_string(options.num_test) + " needs at least " +
                         std::to_string(options.num_train + std::max(options.num_test, 1)) +
                         " frames with a face, got " + std::to_string(kept));

  std::shared_ptr<const face::IctModel> ict;
  if (options.face_model == TrackFaceModel::kIct) {
    ICEF_ASSIGN_OR_RETURN(ict, face::IctModel::LoadDefault());
  }
  ICEF_RETURN_IF_ERROR(ict ? FitIct(*ict, options, &result, log)
                           : FitProcedural(options, executor, &result, log));

  Dataset& d = result.dataset;
  SilhouetteFn silhouette_of;
  if (ict) {
    d.expression_names = ict->expression_names();
    d.aabb = IctHeadBounds(*ict, result.fit.ict_identity, kIctAabbMargin);
    silhouette_of = [&](const TrackedFrame& f, const Camera& camera) {
      return IctSilhouette(*ict, result.fit.ict_identity, f.expression, camera);
    };
  } else {
    d.expression_names = face::ExpressionNames();
    const face::FaceModel model(result.fit.shape);
    d.aabb = model.Bounds();
    d.aabb.min -= Vec3f::Constant(0.1f);
    d.aabb.max += Vec3f::Constant(0.1f);
    silhouette_of = [&executor, model](const TrackedFrame& f, const Camera& camera) {
      return HeadSilhouette(model, f.expression, camera, executor);
    };
  }
  d.expression_dim = static_cast<int>(d.expression_names.size());
  AssignSplits(options, d.expression_names, &result);
  const int used = static_cast<int>(result.photos.size());
  if (log && options.num_train > 0) {
    std::string line = "training frames chosen for coverage of pose and expression:";
    for (const TrackedPhoto& p : result.photos)
      if (!p.test) line += " " + p.name;
    log(line);
  }
  d.background = Vec3f::Ones();
  d.tier_thresholds = std::array<double, 2>{kNearThreshold, kFarThreshold};
  d.train.resize(std::count_if(result.photos.begin(), result.photos.end(),
                               [](const TrackedPhoto& p) { return !p.test; }));
  d.test.resize(used - d.train.size());
  for (int i = 0; i < used; ++i) {
    TrackedPhoto& p = result.photos[i];
    BuildFrame(silhouette_of, result.fit.frames[i], options, segmenter ? &*segmenter : nullptr, &p,
               &(p.test ? d.test : d.train)[p.frame_index]);
  }
  for (Frame& f : d.test) {
    f.delta = ExpressionDistance(f.expression, d.train);
    f.tier = *f.delta == 0                ? Tier::kObserved
             : *f.delta <= kNearThreshold ? Tier::kNear
             : *f.delta <= kFarThreshold  ? Tier::kModerate
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
    for (size_t e = 0; e < f.expression.size(); ++e)
      expression[result.dataset.expression_names[e]] = JsonFloat(f.expression[e]);
    const Vec3d ypr = f.YawPitchRollDeg();
    const Vec3d t = f.cam_from_head.block<3, 1>(0, 3);
    photos.push_back(Json{{"photo", p.source.string()},
                          {"name", p.name},
                          {"time_s", p.time_s ? Json(*p.time_s) : Json()},
                          {"sharpness", p.sharpness},
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
  Json out{{"photos", photos},
           {"skipped", result.skipped},
           {"landmark_rms_iod", result.fit.rms_iod},
           {"photometric_refit", result.fit.photometric},
           {"silhouette_refit", result.fit.silhouettes},
           {"landmark_max_iod", result.fit.max_iod},
           {"iterations", result.fit.iterations}};
  if (result.fit.ict_identity.empty()) {
    Json shape = Json::object();
    const auto values = result.fit.shape.ToArray();
    for (int i = 0; i < face::ShapeParams::kCount; ++i)
      shape[face::kShapeParamNames[i]] = JsonFloat(values[i]);
    out["shape"] = shape;
  } else {
    AddIctReportFields(result.fit, &out);
  }
  return out;
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
    ICEF_RETURN_IF_ERROR(
        WriteFileAtomic(tmp / "track" / "report.json", FormatJson(TrackReportJson(result)) + "\n"));
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
        if (entry.is_regular_file() && (ext == ".png" || ext == ".jpg" || ext == ".jpeg"))
          files.push_back(entry.path());
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
