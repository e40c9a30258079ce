#include "icef/track/dataset_retrack.h"

#include <cmath>
#include <memory>
#include <set>
#include <sstream>
#include <system_error>

#include "icef/core/enum_table.h"
#include "icef/face/expression.h"
#include "icef/face/shape_params.h"
#include "icef/io/atomic_file.h"
#include "icef/io/image.h"
#include "icef/landmarks/landmark_detection.h"
#include "icef/track/head_mask.h"
#include "icef/track/ict_track.h"

namespace icef::track {

namespace {

namespace fs = std::filesystem;

std::vector<Frame>* Split(Dataset& d, const std::string& name) {
  return name == "train" ? &d.train : name == "test" ? &d.test : &d.val;
}

std::string FrameName(const std::string& split, int index, const Frame& f) {
  return split + "[" + std::to_string(index) + "] " + f.file_path;
}

}  // namespace

std::vector<int> SpreadFrames(int n, int max) {
  std::vector<int> frames;
  if (n <= max) {
    for (int i = 0; i < n; ++i) frames.push_back(i);
    return frames;
  }
  for (int i = 0; i < max; ++i)
    frames.push_back(static_cast<int>(std::lround(double(i) * (n - 1) / (max - 1))));
  return frames;
}

constexpr std::array<EnumEntry<RetrackLandmarks>, 3> kRetrackLandmarksNames = {
    {{RetrackLandmarks::kDetect, "detect"},
     {RetrackLandmarks::kDatasetDlib, "dlib"},
     {RetrackLandmarks::kDatasetModel, "model"}}};

const char* RetrackLandmarksName(RetrackLandmarks landmarks) {
  return EnumName(kRetrackLandmarksNames, landmarks);
}

std::optional<RetrackLandmarks> ParseRetrackLandmarks(const std::string& name) {
  return ParseEnum(kRetrackLandmarksNames, name);
}

double RetrackPhotometricWeight(RetrackLandmarks landmarks) {
  return landmarks == RetrackLandmarks::kDatasetModel ? 0.0 : TrackFitOptions().photometric_weight;
}

int RetrackSilhouettePoints(RetrackLandmarks landmarks) {
  return landmarks == RetrackLandmarks::kDatasetModel ? 0 : 200;
}

double RetrackLandmarkSigma(RetrackLandmarks landmarks) {
  return landmarks == RetrackLandmarks::kDatasetModel ? kRetrackModelLandmarkSigmaIod
                                                      : kRetrackLandmarkSigmaIod;
}

Status RetrackOptions::Validate() const {
  if (face_model == TrackFaceModel::kIct) ICEF_RETURN_IF_ERROR(ict_fit.Validate());
  TrackFitOptions resolved = fit;
  if (resolved.photometric_weight < 0) resolved.photometric_weight = RetrackPhotometricWeight(landmarks);
  if (resolved.landmark_sigma_iod < 0) resolved.landmark_sigma_iod = RetrackLandmarkSigma(landmarks);
  return resolved.Validate();
}

std::string RetrackOptions::ToString() const {
  return "RetrackOptions(landmarks=" + std::string(RetrackLandmarksName(landmarks)) +
         ", skip_bad=" + std::to_string(skip_bad) +
         ", silhouette_points=" + std::to_string(silhouette_points) +
         ", detector=" + LandmarkDetectorName(detector) +
         ", predictor=" + (predictor_path.empty() ? std::string("default") : predictor_path.string()) +
         ", fit_style=" + std::to_string(fit_style) + ", face_model=" + TrackFaceModelName(face_model) +
         ", " + (face_model == TrackFaceModel::kIct ? ict_fit.ToString() : fit.ToString()) + ")";
}

namespace {

// The ICT fit of RetrackDataset: the frames' landmarks with their known cameras (FitIctTrack), the
// dataset in ICT's expressions with the fitted mesh's landmarks (world frame).
Status RetrackIct(const std::vector<TrackFrame>& track_frames, const std::vector<Frame*>& order,
                  const RetrackOptions& options, const std::function<void(const std::string&)>& log,
                  RetrackResult* result) {
  ICEF_ASSIGN_OR_RETURN(const std::shared_ptr<const face::IctModel> model, face::IctModel::LoadDefault());
  Result<TrackFit> fit = FitIctTrack(*model, track_frames, options.ict_fit);
  if (!fit.ok()) return fit.status().WithContext("ICT-FaceKit fit");
  result->fit = std::move(fit).value();
  if (log) {
    std::ostringstream os;
    os << "ICT-FaceKit fitted to the landmarks of " << order.size() << " frames with their cameras held: RMS "
       << result->fit.rms_iod << " IOD (max " << result->fit.max_iod << "), " << result->fit.iterations
       << " iterations";
    log(os.str());
  }
  for (size_t k = 0; k < order.size(); ++k) {
    Frame& f = *order[k];
    f.expression = result->fit.frames[k].expression;
    f.landmarks_3d = std::vector<Vec3f>(result->fit.frames[k].landmarks_head.begin(),
                                        result->fit.frames[k].landmarks_head.end());
    f.neutral_landmarks_2d.reset();  // in the source's terms; the neutral image is kept
    f.neutral_landmarks_3d.reset();
  }
  result->dataset.expression_dim = model->num_expressions();
  result->dataset.expression_names = model->expression_names();
  return Status::Ok();
}

}  // namespace

Result<RetrackResult> RetrackDataset(const Dataset& source, const RetrackOptions& options,
                                     const Executor& executor,
                                     const std::function<void(const std::string&)>& log) {
  ICEF_RETURN_IF_ERROR(options.Validate().WithContext("track fit options"));
  RetrackResult result;
  result.dataset = source;
  Dataset& d = result.dataset;

  // Landmarks: dlib's, detected anew in every frame, unless the dataset's own are to be used.
  if (options.landmarks == RetrackLandmarks::kDetect) {
    LandmarkDetectionOptions lo;
    lo.predictor_path = options.predictor_path;
    lo.overwrite = true;
    lo.averaged = true;  // as icef track detects (and as detector_landmarks.inc was measured)
    lo.mesh = options.detector == LandmarkDetector::kMesh;
    if (log)
      log(std::string("detecting the landmarks of every frame (") + LandmarkDetectorName(options.detector) +
          ")");
    ICEF_ASSIGN_OR_RETURN(const LandmarkDetectionReport report, DetectDatasetLandmarks(source, lo, executor));
    for (const FrameLandmarks& fl : report.frames) {
      Frame& f = (*Split(d, fl.split))[fl.index];
      if (fl.outcome != LandmarkOutcome::kDetected && f.landmarks_2d) {
        // The detector found no face (small frames at a three-quarter view): the dataset's own
        // landmarks stand in, in their own convention.
        const std::string name = FrameName(fl.split, fl.index, f);
        result.fallbacks.push_back(name);
        if (log) log(name + ": no face found; fitting the dataset's own landmarks_2d instead");
        continue;
      }
      f.landmarks_2d.reset();
      f.landmarks_2d_visible.reset();
      if (fl.outcome == LandmarkOutcome::kDetected) f.landmarks_2d = fl.detection.landmarks;
    }
  }
  // Frames without landmarks: an error, or dropped.
  for (const std::string split : {"train", "test", "val"}) {
    std::vector<Frame>* frames = Split(d, split);
    std::vector<Frame> kept;
    for (size_t i = 0; i < frames->size(); ++i) {
      if ((*frames)[i].landmarks_2d) {
        kept.push_back((*frames)[i]);
        continue;
      }
      const std::string name = FrameName(split, static_cast<int>(i), (*frames)[i]);
      const std::string why =
          options.landmarks == RetrackLandmarks::kDetect ? "no face found" : "no landmarks_2d";
      if (!options.skip_bad)
        return Status::Error(source.root.string() + ": " + name + ": " + why +
                             " (--skip-bad drops such frames)");
      result.skipped.push_back(name + ": " + why);
      if (log) log("skipped " + name + ": " + why);
    }
    *frames = std::move(kept);
  }
  if (d.train.empty()) return Status::Error(source.root.string() + ": no training frame with a face");

  std::vector<TrackFrame> track_frames;
  std::vector<Frame*> order;
  for (const std::string split : {"train", "test", "val"}) {
    std::vector<Frame>* frames = Split(d, split);
    for (size_t i = 0; i < frames->size(); ++i) {
      Frame& f = (*frames)[i];
      track_frames.push_back(
          TrackFrame{*f.landmarks_2d, f.camera.intrinsics(), f.camera.world_from_cam(), {}});
      order.push_back(&f);
      result.frame_names.push_back(FrameName(split, static_cast<int>(i), f));
    }
  }
  if (options.face_model == TrackFaceModel::kIct) {
    ICEF_RETURN_IF_ERROR(RetrackIct(track_frames, order, options, log, &result));
    return result;
  }
  TrackFitOptions fit_options = options.fit;
  const bool default_weight = fit_options.photometric_weight < 0;
  if (default_weight) fit_options.photometric_weight = RetrackPhotometricWeight(options.landmarks);
  if (fit_options.landmark_sigma_iod < 0)
    fit_options.landmark_sigma_iod = RetrackLandmarkSigma(options.landmarks);
  const int silhouette_points =
      options.silhouette_points < 0 ? RetrackSilhouettePoints(options.landmarks) : options.silhouette_points;
  // The images: for the photometric refit (track_fit.h), composited over the dataset's background;
  // their alpha masks' edges for the silhouette term. Loaded one at a time unless the refit keeps them.
  const bool photometric =
      fit_options.photometric_weight > 0 && order.size() <= static_cast<size_t>(kMaxPhotometricFrames);
  if (fit_options.photometric_weight > 0 && !photometric && log)
    log("photometric refit skipped: " + std::to_string(order.size()) + " frames (at most " +
        std::to_string(kMaxPhotometricFrames) + "); the landmarks alone give the expressions");
  std::vector<Image> photos;
  photos.reserve(order.size());  // track_frames point into it
  // Frames without alpha in a dataset with a background image (NerFace: a static camera's empty
  // scene): the mask is where they differ from it.
  std::optional<Image> background_image;
  if (silhouette_points > 0 && d.background_file_path) {
    Result<Image> bg = ReadImage(d.root / *d.background_file_path);
    if (!bg.ok())
      return bg.status().WithContext((d.root / *d.background_file_path).string() + ": background_file_path");
    background_image = std::move(*bg);
  }
  int masked = 0, differenced = 0;
  std::vector<char> outlined(order.size(), 0);
  if (silhouette_points > 0)
    for (const int k : SpreadFrames(static_cast<int>(order.size()), kMaxSilhouetteFrames)) outlined[k] = 1;
  if (photometric || silhouette_points > 0) {
    for (size_t k = 0; k < order.size(); ++k) {
      if (!photometric && !outlined[k]) continue;
      ICEF_ASSIGN_OR_RETURN(Image rgba, LoadFrameImage(d, *order[k]));
      const bool by_background = !rgba.HasAlpha() && background_image &&
                                 background_image->width == rgba.width &&
                                 background_image->height == rgba.height;
      if (outlined[k] && (rgba.HasAlpha() || by_background)) {
        Image mask(rgba.width, rgba.height, 1);
        if (by_background) {
          mask = BackgroundDifferenceMask(rgba, *background_image);
        } else {
          for (int y = 0; y < rgba.height; ++y)
            for (int x = 0; x < rgba.width; ++x) mask.At(x, y, 0) = rgba.At(x, y, 3);
        }
        std::vector<Vec2f> points = MaskEdgePoints(mask, Image(), silhouette_points);
        if (fit_options.silhouette_face_only) {  // as photo tracking: where skin lies just inside the edge
          const std::vector<Vec2f>& lm = track_frames[k].landmarks_2d;
          const float iod = ((lm[36] + lm[39]) * 0.5f - (lm[42] + lm[45]) * 0.5f).norm();
          if (std::isfinite(iod) && iod > 0) {  // else no skin model: every point stays
            const std::vector<bool> keep = SkinEdges(rgba, mask, points, FitSkinModel(rgba, lm), 0.08 * iod);
            std::vector<Vec2f> skin;
            for (size_t i = 0; i < points.size(); ++i)
              if (keep[i]) skin.push_back(points[i]);
            points = std::move(skin);
          }
        }
        track_frames[k].silhouette = std::move(points);
        (by_background ? differenced : masked) += !track_frames[k].silhouette.empty();
      }
      if (!photometric) continue;
      Image rgb(rgba.width, rgba.height, 3);
      for (int y = 0; y < rgba.height; ++y)
        for (int x = 0; x < rgba.width; ++x) {
          const float a = rgba.HasAlpha() ? rgba.At(x, y, 3) : 1.f;
          for (int c = 0; c < 3; ++c) rgb.At(x, y, c) = a * rgba.At(x, y, c) + (1 - a) * d.background[c];
        }
      photos.push_back(std::move(rgb));
      track_frames[k].photo = &photos.back();
    }
  }
  if (silhouette_points > 0 && log) {
    const std::string part = fit_options.silhouette_face_only ? "the face's part" : "the whole head";
    if (masked > 0)
      log("silhouettes: the alpha masks' outlines of " + std::to_string(masked) + " of " +
          std::to_string(order.size()) + " frames (" + part + ")");
    if (masked + differenced > 0 && order.size() > static_cast<size_t>(kMaxSilhouetteFrames))
      log("silhouettes: at most " + std::to_string(kMaxSilhouetteFrames) +
          " frames, spread over the sequence, add their outlines; the others keep their landmarks");
    if (differenced > 0)
      log("silhouettes: the outlines of " + std::to_string(differenced) + " of " +
          std::to_string(order.size()) + " frames against the background image " + *d.background_file_path +
          " (" + part + ")");
    if (masked + differenced == 0)
      log("silhouettes: no frame has an alpha mask or a background image to tell it from; landmarks only");
  }
  // Outlines place the similarity: the refit then holds it and reads the expressions, by default at
  // a higher weight (without them its colours help place the head, at the landmarks' default).
  result.outlined_frames = masked + differenced;
  if (result.outlined_frames > 0 && photometric) {
    fit_options.photometric_hold_similarity = true;
    if (default_weight) fit_options.photometric_weight = kRetrackPhotometricWeightWithOutlines;
    if (log)
      log("photometric refit: weight " +
          std::to_string(static_cast<int>(std::lround(fit_options.photometric_weight))) +
          ", the similarity the outlines placed held; the colours read the expressions");
  }
  result.photometric_weight = photometric ? fit_options.photometric_weight : 0.0;
  result.similarity_held = fit_options.photometric_hold_similarity;
  fit_options.detector =
      options.landmarks == RetrackLandmarks::kDetect ? options.detector : LandmarkDetector::kDlib;
  if (options.landmarks == RetrackLandmarks::kDatasetModel) {
    // The face model's own landmarks, as exact as the data that carries them: the priors of a
    // sub-pixel source (track_fit_test's), not those balanced against dlib's scatter.
    fit_options.dlib_convention = false;
    fit_options.shape_prior_sigma = 0.15;
    fit_options.expression_prior_sigma = 0.6;
    fit_options.photometric_expression_prior_sigma = 0.6;
  }
  ICEF_ASSIGN_OR_RETURN(result.fit, FitTrack(track_frames, fit_options));
  if (log) log(result.fit.BriefReport());
  if (options.landmarks == RetrackLandmarks::kDatasetModel && options.fit_style) {
    // The weights just read are generic-style weights. Exact landmarks show how this subject
    // performs them (a jaw hinged elsewhere, a wider smile), which a generic weight cannot stand in
    // for far from the frames: fit the style to the landmarks at those weights, then read the
    // weights again in it.
    std::vector<face::FitFrame> style_frames(track_frames.size());
    for (size_t k = 0; k < track_frames.size(); ++k) {
      style_frames[k].expression = result.fit.frames[k].expression;
      style_frames[k].landmarks_2d = track_frames[k].landmarks_2d;
      style_frames[k].camera = Camera(track_frames[k].intrinsics, *track_frames[k].world_from_cam);
    }
    face::FaceFitOptions style_options;
    style_options.fit_style = true;
    Result<face::FaceFit> style_fit = face::FitFaceModel(style_frames, style_options);
    if (!style_fit.ok()) return style_fit.status().WithContext("expression style fit");
    result.style_fit = *style_fit;
    if (log) log("the subject's expression style, at the weights read: " + style_fit->BriefReport());
    if (!style_fit->style_rejected) {
      fit_options.style = style_fit->style;
      ICEF_ASSIGN_OR_RETURN(result.fit, FitTrack(track_frames, fit_options));
      if (log) log("in that style, " + result.fit.BriefReport());
    }
  }
  const face::Similarity& sim = *result.fit.head_from_world;
  for (size_t k = 0; k < order.size(); ++k) {
    Frame& f = *order[k];
    f.expression = result.fit.frames[k].expression;
    std::vector<Vec3f> world;
    for (const Vec3f& p : result.fit.frames[k].landmarks_head)
      world.push_back(sim.ApplyInverse(p.cast<double>()).cast<float>());
    f.landmarks_3d = world;
    f.neutral_landmarks_2d.reset();  // in the source's terms; the neutral image is kept
    f.neutral_landmarks_3d.reset();
  }
  d.expression_dim = face::kNumExpressions;
  d.expression_names = face::ExpressionNames();
  return result;
}

Json RetrackReportJson(const RetrackResult& result) {
  Json frames = Json::array();
  const std::vector<std::string>& names = result.dataset.expression_names;
  for (size_t k = 0; k < result.fit.frames.size(); ++k) {
    const TrackedFrame& f = result.fit.frames[k];
    Json expression = Json::object();
    for (size_t e = 0; e < f.expression.size() && e < names.size(); ++e)
      expression[names[e]] = JsonFloat(f.expression[e]);
    frames.push_back(Json{{"frame", result.frame_names[k]},
                          {"landmark_rms_iod", f.rms_iod},
                          {"landmark_max_iod", f.max_iod},
                          {"landmarks_used", f.landmarks_used},
                          {"silhouette_rms_iod", f.silhouette_rms_iod},
                          {"silhouette_points_used", f.silhouette_used},
                          {"photometric_rms", f.photometric_rms},
                          {"photometric_points_used", f.photometric_used},
                          {"expression", expression}});
  }
  Json shape = Json::object();
  const auto values = result.fit.shape.ToArray();
  for (int i = 0; i < face::ShapeParams::kCount; ++i) shape[face::kShapeParamNames[i]] = JsonFloat(values[i]);
  const face::Similarity& s = *result.fit.head_from_world;
  Json rotation = Json::array();
  for (int r = 0; r < 3; ++r) rotation.push_back({s.rotation(r, 0), s.rotation(r, 1), s.rotation(r, 2)});
  Json style = nullptr;  // null: the weights are the generic style's and no style was fitted
  if (result.style_fit) {
    Json fields = Json::object();
    for (const auto& [name, value] : result.style_fit->style.Fields()) fields[name] = JsonFloat(value);
    style = Json{{"fields", fields},
                 {"f", result.style_fit->style_f},
                 {"kept", !result.style_fit->style_rejected},
                 {"landmark_rms_iod", result.style_fit->rms_iod},
                 {"generic_landmark_rms_iod", result.style_fit->generic_style_rms_iod}};
  }
  Json out{{"frames", frames},
           {"skipped", result.skipped},
           {"expression_style", style},
           {"landmark_rms_iod", result.fit.rms_iod},
           {"photometric_refit", result.fit.photometric},
           {"silhouette_refit", result.fit.silhouettes},
           {"landmark_max_iod", result.fit.max_iod},
           {"iterations", result.fit.iterations},
           {"head_from_world",
            {{"scale", s.scale},
             {"rotation", rotation},
             {"translation", {s.translation.x(), s.translation.y(), s.translation.z()}}}},
           {"shape", shape}};
  if (!result.fit.ict_identity.empty()) {  // ICT: its identity instead of the procedural shape
    AddIctReportFields(result.fit, &out);
    out.erase("shape");
  }
  return out;
}

Status WriteRetrackedDataset(const RetrackResult& result, const fs::path& out_dir,
                             const std::vector<std::pair<std::string, Image>>& extra_images) {
  return CreateDirectoryAtomic(out_dir, [&](const fs::path& tmp) -> Status {
    const Dataset& src = result.dataset;
    std::set<std::string> files;
    for (const auto* frames : {&src.train, &src.test, &src.val})
      for (const Frame& f : *frames) {
        files.insert(f.file_path);
        if (f.neutral_file_path) files.insert(*f.neutral_file_path);
      }
    if (src.background_file_path) files.insert(*src.background_file_path);
    std::error_code ec;
    for (const std::string& rel : files) {
      fs::create_directories((tmp / rel).parent_path(), ec);
      if (!fs::copy_file(src.root / rel, tmp / rel, ec))
        return Status::Error((src.root / rel).string() + ": cannot copy the image: " + ec.message());
    }
    Dataset d = src;
    d.root = tmp;
    ICEF_RETURN_IF_ERROR(SaveDataset(d));
    fs::create_directories(tmp / "track", ec);
    for (const auto& [name, image] : extra_images) {
      fs::create_directories((tmp / name).parent_path(), ec);
      ICEF_RETURN_IF_ERROR(WritePng(tmp / name, image));
    }
    return WriteFileAtomic(tmp / "track" / "report.json", FormatJson(RetrackReportJson(result)) + "\n");
  });
}

}  // namespace icef::track
