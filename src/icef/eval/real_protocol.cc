#include "icef/eval/real_protocol.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "icef/data/landmark_region.h"
#include "icef/eval/expression_fidelity.h"
#include "icef/eval/metrics.h"
#include "icef/model/method.h"
#include "icef/model/render_image.h"

namespace fs = std::filesystem;

namespace icef::eval {

namespace {

// The measures, written once: the JSON key (the same in a frame and in the means), the frame's
// value and its mean.
struct RealField {
  const char* key;
  std::optional<double> RealFrameMetrics::*frame;
  std::optional<double> RealMeans::*mean;
};
constexpr std::array<RealField, 9> kFields = {{
    {"face_psnr", &RealFrameMetrics::face_psnr, &RealMeans::face_psnr},
    {"face_ssim", &RealFrameMetrics::face_ssim, &RealMeans::face_ssim},
    {"head_psnr", &RealFrameMetrics::head_psnr, &RealMeans::head_psnr},
    {"head_ssim", &RealFrameMetrics::head_ssim, &RealMeans::head_ssim},
    {"lpips", &RealFrameMetrics::lpips, &RealMeans::lpips},
    {"id_distance", &RealFrameMetrics::id_distance, &RealMeans::id_distance},
    {"real_expr_gain", &RealFrameMetrics::real_expr_gain, &RealMeans::real_expr_gain},
    {"face_psnr_nearest", &RealFrameMetrics::face_psnr_nearest, &RealMeans::face_psnr_nearest},
    {"track_rms_iod", &RealFrameMetrics::track_rms_iod, &RealMeans::track_rms_iod},
}};

// The inner landmarks (brows, eyes, nose, mouth: 17-67) are points of the face's surface; the jaw
// outline (0-16) is where the cheek turns away from the camera, which a detector and the face
// model's fixed contour vertices place differently at every view.
constexpr int kFirstInnerLandmark = 17;

Json OptionalJson(const std::optional<double>& v) { return v ? Json(*v) : Json(nullptr); }
std::optional<double> Finite(double v) { return std::isfinite(v) ? std::optional<double>(v) : std::nullopt; }

Result<std::optional<double>> ReadOptional(const Json& j, const std::string& where, const char* key) {
  const auto it = j.find(key);
  if (it == j.end() || it->is_null()) return std::optional<double>();
  if (!it->is_number() || !std::isfinite(it->get<double>()))
    return Status::Error(where + "." + key + ": expected a finite number or null");
  return std::optional<double>(it->get<double>());
}

std::string ReadString(const Json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}

std::string RenderName(const std::string& file_path, const char* suffix) {
  return "renders/" + fs::path(file_path).stem().string() + suffix + ".png";
}

// PSNR and SSIM inside a mask, null where the mask leaves nothing to measure.
void MaskedMetrics(const Image& render, const Image& photo, const Image& mask, std::optional<double>* psnr,
                   std::optional<double>* ssim) {
  Result<double> p = Psnr(render, photo, &mask);
  if (p.ok()) *psnr = Finite(*p);
  Result<double> s = Ssim(render, photo, {}, &mask);
  if (s.ok()) *ssim = Finite(*s);
}

}  // namespace

Json RealFrameMetrics::ToJson() const {
  Json j;
  j["file_path"] = file_path;
  j["delta"] = delta;
  j["nearest_train"] = nearest_train;
  for (const RealField& f : kFields) j[f.key] = OptionalJson(this->*f.frame);
  j["render"] = render_path;
  j["render_nearest"] = nearest_path;
  return j;
}

Result<RealFrameMetrics> RealFrameMetrics::FromJson(const Json& j, const std::string& where) {
  if (!j.is_object()) return Status::Error(where + ": expected an object");
  RealFrameMetrics m;
  m.file_path = ReadString(j, "file_path");
  if (m.file_path.empty()) return Status::Error(where + ".file_path: expected a string");
  if (j.contains("delta") && j["delta"].is_number()) m.delta = j["delta"].get<double>();
  if (j.contains("nearest_train") && j["nearest_train"].is_number_integer())
    m.nearest_train = j["nearest_train"].get<int>();
  for (const RealField& f : kFields) {
    ICEF_ASSIGN_OR_RETURN(m.*f.frame, ReadOptional(j, where, f.key));
  }
  m.render_path = ReadString(j, "render");
  m.nearest_path = ReadString(j, "render_nearest");
  return m;
}

RealMeans RealMeans::Of(const std::vector<RealFrameMetrics>& frames) {
  RealMeans means;
  means.count = static_cast<int>(frames.size());
  for (const RealField& f : kFields) {
    double sum = 0;
    int n = 0;
    for (const RealFrameMetrics& m : frames)
      if (const auto& v = m.*f.frame) {
        sum += *v;
        ++n;
      }
    if (n > 0) means.*f.mean = sum / n;
  }
  return means;
}

Json RealMeans::ToJson() const {
  Json j;
  j["count"] = count;
  for (const RealField& f : kFields) j[f.key] = OptionalJson(this->*f.mean);
  return j;
}

Result<RealMeans> RealMeans::FromJson(const Json& j, const std::string& where) {
  if (!j.is_object()) return Status::Error(where + ": expected an object");
  RealMeans m;
  if (j.contains("count") && j["count"].is_number_integer()) m.count = j["count"].get<int>();
  for (const RealField& f : kFields) {
    ICEF_ASSIGN_OR_RETURN(m.*f.mean, ReadOptional(j, where, f.key));
  }
  return m;
}

Json RealEvalResult::ToJson() const {
  Json frames_json = Json::array();
  for (const RealFrameMetrics& f : frames) frames_json.push_back(f.ToJson());
  return Json{{"method", method},
              {"identity_available", identity_available},
              {"lpips_available", lpips_available},
              {"means", means.ToJson()},
              {"frames", frames_json}};
}

Result<RealEvalResult> RealEvalResult::FromJson(const Json& j, const std::string& where) {
  if (!j.is_object()) return Status::Error(where + ": expected an object");
  RealEvalResult r;
  r.method = ReadString(j, "method");
  r.identity_available = j.value("identity_available", false);
  r.lpips_available = j.value("lpips_available", false);
  const auto frames = j.find("frames");
  if (frames == j.end() || !frames->is_array()) return Status::Error(where + ".frames: expected an array");
  for (size_t i = 0; i < frames->size(); ++i) {
    ICEF_ASSIGN_OR_RETURN(
        RealFrameMetrics f,
        RealFrameMetrics::FromJson((*frames)[i], where + ".frames[" + std::to_string(i) + "]"));
    r.frames.push_back(std::move(f));
  }
  r.means = RealMeans::Of(r.frames);
  return r;
}

std::optional<double> RealExpressionGain(const Image& photo, const Image& tracked, const Image& nearest,
                                         const Image& region) {
  ICEF_CHECK(photo.width == tracked.width && photo.width == nearest.width && photo.width == region.width &&
                 photo.height == tracked.height && photo.height == nearest.height &&
                 photo.height == region.height,
             "RealExpressionGain: images of one size");
  double err_tracked = 0, err_nearest = 0;
  int pixels = 0;
  for (int y = 0; y < photo.height; ++y)
    for (int x = 0; x < photo.width; ++x) {
      if (region.At(x, y, 0) <= 0.5f) continue;
      ++pixels;
      const Vec3f p = photo.Rgb(x, y);
      err_tracked += (tracked.Rgb(x, y) - p).squaredNorm();
      err_nearest += (nearest.Rgb(x, y) - p).squaredNorm();
    }
  if (pixels == 0 || !(err_nearest > 0)) return std::nullopt;
  return (err_nearest - err_tracked) / err_nearest;
}

std::optional<double> TrackingResidualIod(const Frame& frame) {
  if (!frame.landmarks_2d || !frame.landmarks_3d || frame.landmarks_2d->size() != 68 ||
      frame.landmarks_3d->size() != 68)
    return std::nullopt;
  const std::vector<Vec2f>& lm = *frame.landmarks_2d;
  const Vec2f left = (lm[36] + lm[39]) * 0.5f, right = (lm[42] + lm[45]) * 0.5f;
  const double iod = (left - right).norm();
  if (!(iod > 0)) return std::nullopt;
  double sum = 0;
  int n = 0;
  for (int i = kFirstInnerLandmark; i < 68; ++i) {
    const auto p = frame.camera.Project((*frame.landmarks_3d)[i].cast<double>());
    if (!p || !lm[i].allFinite()) continue;
    sum += (p->uv - lm[i].cast<double>()).squaredNorm();
    ++n;
  }
  if (n == 0) return std::nullopt;
  return std::sqrt(sum / n) / iod;
}

std::pair<int, double> NearestTrainingExpression(const Dataset& dataset,
                                                 const std::vector<float>& expression) {
  int best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < dataset.train.size(); ++k) {
    double s = 0;
    for (size_t i = 0; i < expression.size(); ++i) {
      const double d = expression[i] - dataset.train[k].expression[i];
      s += d * d;
    }
    if (s < best_d) {
      best_d = s;
      best = static_cast<int>(k);
    }
  }
  return {best, std::sqrt(best_d)};
}

Result<RealEvalResult> EvaluateReal(const AvatarModel& model, const Dataset& dataset,
                                    const RealEvalOptions& options, const EvalNetworks& networks,
                                    const Executor& executor, ProgressBar* progress) {
  ICEF_RETURN_IF_ERROR(options.Validate());
  if (dataset.test.empty())
    return Status::Error(dataset.root.string() + ": the dataset has no held-out frames");
  if (dataset.train.empty())
    return Status::Error(dataset.root.string() + ": the dataset has no training frames");
  const bool write = !options.out_dir.empty();
  if (write) {
    std::error_code ec;
    fs::create_directories(options.out_dir / "renders", ec);
    if (ec)
      return Status::Error((options.out_dir / "renders").string() +
                           ": cannot create directory: " + ec.message());
  }
  RealEvalResult result;
  result.method = MethodName(model.method());
  result.identity_available = networks.identity != nullptr;
  result.lpips_available = networks.lpips != nullptr;
  for (size_t i = 0; i < dataset.test.size(); ++i) {
    const Frame& frame = dataset.test[i];
    const std::string where =
        dataset.root.string() + ": held-out frame " + std::to_string(i) + " (" + frame.file_path + ")";
    if (!frame.landmarks_2d) return Status::Error(where + ": landmarks_2d: missing (icef track writes them)");
    ICEF_ASSIGN_OR_RETURN(const Image raw, LoadFrameImage(dataset, frame));
    if (raw.width != frame.camera.width() || raw.height != frame.camera.height())
      return Status::Error(where + ": the image's size differs from the camera's");
    const Image photo = CompositeOver(raw, dataset.background);
    RealFrameMetrics m;
    m.file_path = frame.file_path;
    const auto [nearest, delta] = NearestTrainingExpression(dataset, frame.expression);
    m.nearest_train = nearest;
    m.delta = delta;
    const RenderedImage tracked =
        RenderImage(model, frame.camera, frame.expression, dataset.background, executor);
    const RenderedImage still =
        RenderImage(model, frame.camera, dataset.train[nearest].expression, dataset.background, executor);

    const Image face = FaceRegion(photo.width, photo.height, *frame.landmarks_2d);
    MaskedMetrics(tracked.color, photo, face, &m.face_psnr, &m.face_ssim);
    std::optional<double> unused;
    MaskedMetrics(still.color, photo, face, &m.face_psnr_nearest, &unused);
    if (raw.HasAlpha()) {
      Image head(raw.width, raw.height, 1);
      for (int y = 0; y < raw.height; ++y)
        for (int x = 0; x < raw.width; ++x) head.At(x, y, 0) = raw.At(x, y, 3) > 0.5f ? 1.f : 0.f;
      MaskedMetrics(tracked.color, photo, head, &m.head_psnr, &m.head_ssim);
    }
    const Image region = ExpressionRegion(photo.width, photo.height, *frame.landmarks_2d, {},
                                          DefaultRegionDilation(photo.width));
    m.real_expr_gain = RealExpressionGain(photo, tracked.color, still.color, region);
    m.track_rms_iod = TrackingResidualIod(frame);
    if (networks.lpips) {
      ICEF_ASSIGN_OR_RETURN(const double lpips, networks.lpips->Distance(tracked.color, photo));
      m.lpips = Finite(lpips);
    }
    if (networks.identity) {
      Result<FaceIdentityResult> a = networks.identity->Describe(tracked.color, frame.landmarks_2d);
      Result<FaceIdentityResult> b = networks.identity->Describe(photo, frame.landmarks_2d);
      if (a.ok() && b.ok()) m.id_distance = DescriptorDistance(a->descriptor, b->descriptor);
    }
    if (write) {
      m.render_path = RenderName(frame.file_path, "");
      m.nearest_path = RenderName(frame.file_path, "_nearest");
      ICEF_RETURN_IF_ERROR(WritePng(options.out_dir / m.render_path, tracked.color));
      ICEF_RETURN_IF_ERROR(WritePng(options.out_dir / m.nearest_path, still.color));
    }
    result.frames.push_back(std::move(m));
    if (progress) {
      const RealFrameMetrics& last = result.frames.back();
      char status[96];
      std::snprintf(status, sizeof status, "face psnr %.2f gain %.2f", last.face_psnr.value_or(NAN),
                    last.real_expr_gain.value_or(NAN));
      progress->Update(static_cast<int64_t>(i) + 1, status);
    }
  }
  result.means = RealMeans::Of(result.frames);
  return result;
}

}  // namespace icef::eval
