#include "icef/app/curves_app.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <utility>

#include "icef/core/parallel.h"
#include "icef/core/progress.h"
#include "icef/io/atomic_file.h"
#include "icef/landmarks/face_landmark_detector.h"
#include "icef/landmarks/face_mesh.h"
#include "icef/track/ict_track.h"
#include "icef/track/photo_crop.h"
#include "icef/track/photo_track.h"
#include "icef/video/video_decoder.h"
#include "icef/video/video_reader.h"

namespace icef {

namespace {

namespace fs = std::filesystem;

// A frame's landmarks, or none (no face, or several).
struct Detected {
  double time_s = 0;
  std::optional<std::vector<Vec2f>> landmarks;
};

// The face's landmarks in each image (in parallel, one detector per chunk).
void DetectBatch(const std::vector<Image>& images, const FaceLandmarkDetector& detector, const FaceMesh* mesh,
                 const Executor& executor, std::span<Detected> out) {
  ParallelFor(executor, static_cast<int64_t>(images.size()), [&](int64_t begin, int64_t end, int) {
    const FaceLandmarkDetector local = detector.Clone();
    for (int64_t i = begin; i < end; ++i) {
      const Result<FaceDetection> d = track::DetectTrackLandmarks(local, mesh, images[i]);
      if (d.ok() && d->num_faces == 1) out[i].landmarks = d->landmarks;
    }
  });
}

struct DecodedVideo {
  std::vector<Detected> frames;
  Intrinsics intrinsics;
  double fps = 0;  // of the kept frames
};

// Decodes the kept frames, detecting each batch's landmarks as it fills; only landmarks are kept.
Result<DecodedVideo> DecodeAndDetect(const TrackAppOptions& options, std::ostream& out) {
  const fs::path& video = options.photos[0];
  ICEF_ASSIGN_OR_RETURN(std::unique_ptr<VideoDecoder> decoder, VideoDecoder::Open(video));
  const VideoInfo info = decoder->info();
  char head[200];
  std::snprintf(head, sizeof head, "icef track --curves: %s, %dx%d, %.1f s at %.2f fps (%s)",
                video.string().c_str(), info.width, info.height, info.duration_s, info.fps,
                info.codec.c_str());
  out << head << "\n";
  ICEF_ASSIGN_OR_RETURN(const FaceLandmarkDetector detector, FaceLandmarkDetector::Load(options.predictor));
  std::optional<FaceMesh> mesh;
  if (options.track.fit.detector == track::LandmarkDetector::kMesh) {
    ICEF_ASSIGN_OR_RETURN(FaceMesh loaded, FaceMesh::Load());
    mesh = std::move(loaded);
  }
  const Executor executor(options.threads);
  const int every = std::max(1, options.every);
  DecodedVideo result;
  result.fps = info.fps / every;
  ProgressBar bar("track", std::max<int64_t>(info.frame_count_estimate, 1), out, options.interactive);
  std::vector<Image> batch;
  const size_t batch_size = 4 * static_cast<size_t>(std::max(1, executor.num_threads()));
  auto flush = [&] {
    const size_t first = result.frames.size() - batch.size();
    DetectBatch(batch, detector, mesh ? &*mesh : nullptr, executor,
                std::span<Detected>(result.frames).subspan(first, batch.size()));
    batch.clear();
  };
  for (;;) {
    ICEF_ASSIGN_OR_RETURN(const bool more, decoder->Next());
    if (!more) break;
    const int64_t i = decoder->index();
    if (i % every == 0) {
      ICEF_ASSIGN_OR_RETURN(const Rgb8Frame rgb, decoder->CurrentRgb());
      batch.push_back(rgb.ToImage());
      result.frames.push_back(Detected{decoder->time_s(), std::nullopt});
      if (batch.size() == batch_size) flush();
    }
    bar.Update(i + 1);
    if (options.max_frames > 0 && result.frames.size() >= size_t(options.max_frames)) break;
  }
  if (!batch.empty()) flush();
  bar.Finish(std::to_string(result.frames.size()) + " frames");
  result.intrinsics.width = info.width;
  result.intrinsics.height = info.height;
  result.intrinsics.cx = 0.5 * info.width;
  result.intrinsics.cy = 0.5 * info.height;
  result.intrinsics.fl_x = result.intrinsics.fl_y =
      options.track.focal ? *options.track.focal : track::DefaultFocalPixels(info.width, info.height);
  return result;
}

// "HH:MM:SS:FF.mmm": the frame within its second, and the thousandths of a frame.
std::string Timecode(double t, double fps) {
  const double whole = std::floor(t);
  const int s = static_cast<int>(whole);
  const double frame = (t - whole) * std::max(fps, 1.0);
  char buf[40];
  std::snprintf(buf, sizeof buf, "%02d:%02d:%02d:%02d.%03d", s / 3600, (s / 60) % 60, s % 60,
                static_cast<int>(std::floor(frame + 1e-6)),
                static_cast<int>(std::lround((frame - std::floor(frame + 1e-6)) * 1000)) % 1000);
  return buf;
}

// Frames without a face take the curves of the nearest frame with one (the earlier one on a tie).
void FillUntracked(std::vector<CurveFrame>& frames) {
  std::vector<int> tracked;
  for (int i = 0; i < static_cast<int>(frames.size()); ++i)
    if (frames[i].tracked) tracked.push_back(i);
  for (int i = 0; i < static_cast<int>(frames.size()); ++i) {
    if (frames[i].tracked) continue;
    const auto next = std::lower_bound(tracked.begin(), tracked.end(), i);
    int src = next == tracked.end() ? tracked.back() : *next;
    if (next != tracked.begin() && (next == tracked.end() || i - *(next - 1) <= *next - i)) src = *(next - 1);
    const double time_s = frames[i].time_s;
    frames[i] = frames[src];
    frames[i].time_s = time_s;
    frames[i].tracked = false;
  }
}

}  // namespace

std::string ArkitCurvesCsv(const face::IctModel& model, std::span<const CurveFrame> frames, double fps) {
  const std::vector<std::string> names = model.ArkitNames();
  std::string csv = "Timecode,BlendShapeCount";
  for (const std::string& n : names) {
    std::string column = n;
    column[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(column[0])));
    csv += "," + column;
  }
  csv += ",HeadYaw,HeadPitch,HeadRoll\n";
  std::vector<std::vector<int>> targets;
  for (const std::string& n : names) targets.push_back(model.ExpressionTargets(n));
  const int count = static_cast<int>(names.size()) + 3;
  char cell[32];
  for (const CurveFrame& f : frames) {
    csv += Timecode(f.time_s, fps) + "," + std::to_string(count);
    for (const std::vector<int>& t : targets) {
      double sum = 0;
      for (int e : t) sum += f.weights[e];
      std::snprintf(cell, sizeof cell, ",%.4f", sum / t.size());
      csv += cell;
    }
    for (double angle : {f.yaw, f.pitch, f.roll}) {
      std::snprintf(cell, sizeof cell, ",%.5f", angle);
      csv += cell;
    }
    csv += "\n";
  }
  return csv;
}

Status RunTrackCurves(const TrackAppOptions& options, const fs::path& csv, std::ostream& out) {
  if (options.photos.size() != 1 || !LooksLikeVideo(options.photos[0]))
    return Status::Error("icef track --curves: give one video (.mp4, .mov, .mkv, .avi, .webm, .m4v)");
  if (!options.out.empty() || options.keep_cameras || options.track.num_train > 0 ||
      options.track.num_test > 0)
    return Status::Error(
        "icef track --curves writes curves, not a dataset: leave out --out, --frames, --test "
        "and --keep-cameras");
  ICEF_ASSIGN_OR_RETURN(const std::shared_ptr<const face::IctModel> model, face::IctModel::LoadDefault());
  ICEF_ASSIGN_OR_RETURN(const DecodedVideo video, DecodeAndDetect(options, out));
  std::vector<track::TrackFrame> observed;
  std::vector<CurveFrame> rows(video.frames.size());
  for (size_t i = 0; i < video.frames.size(); ++i) {
    rows[i].time_s = video.frames[i].time_s;
    rows[i].tracked = video.frames[i].landmarks.has_value();
    if (rows[i].tracked)
      observed.push_back(track::TrackFrame{*video.frames[i].landmarks, video.intrinsics, {}, {}, nullptr});
  }
  if (observed.empty())
    return Status::Error(options.photos[0].string() + ": no frame with exactly one face; nothing to track");
  ICEF_ASSIGN_OR_RETURN(const track::TrackFit fit,
                        track::FitIctTrack(*model, observed, options.track.ict_fit));
  for (size_t i = 0, k = 0; i < rows.size(); ++i) {
    if (!rows[i].tracked) continue;
    const track::TrackedFrame& f = fit.frames[k++];
    const Vec3d ypr = f.YawPitchRollDeg() * (M_PI / 180);
    rows[i].weights = f.expression;
    rows[i].yaw = ypr.x(), rows[i].pitch = ypr.y(), rows[i].roll = ypr.z();
  }
  FillUntracked(rows);
  ICEF_RETURN_IF_ERROR(WriteFileAtomic(csv, ArkitCurvesCsv(*model, rows, video.fps)));
  const size_t missed = rows.size() - observed.size();
  char line[320];
  std::snprintf(line, sizeof line,
                "ICT-FaceKit fit to the landmarks of %zu frames: RMS %.3f IOD (max %.3f); the driving "
                "person's identity stays in the fit, out of the curves",
                observed.size(), fit.rms_iod, fit.max_iod);
  out << line << "\n";
  if (missed > 0) {
    out << missed << " frame" << (missed == 1 ? "" : "s")
        << " without exactly one face took the curves of the nearest frame with one, at";
    int listed = 0;
    for (const CurveFrame& r : rows) {
      if (r.tracked) continue;
      if (++listed > 10) {
        out << " ...";
        break;
      }
      std::snprintf(line, sizeof line, " %.2f s", r.time_s);
      out << line;
    }
    out << "\n";
  }
  out << "wrote " << csv.string() << ": " << rows.size() << " rows at " << video.fps << " fps, "
      << model->ArkitNames().size() << " ARKit curves and the head's yaw, pitch and roll\n";
  return Status::Ok();
}

}  // namespace icef
