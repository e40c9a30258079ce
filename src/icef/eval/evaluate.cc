#include "icef/eval/evaluate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "icef/eval/expression_fidelity.h"
#include "icef/eval/metrics.h"
#include "icef/io/atomic_file.h"
#include "icef/model/render_image.h"
#include "icef/synth/synthesize.h"

namespace fs = std::filesystem;

namespace icef::eval {

const std::array<Tier, kNumTiers>& AllTiers() {
  static const std::array<Tier, kNumTiers> kTiers = {Tier::kObserved, Tier::kNear, Tier::kModerate,
                                                     Tier::kFar};
  return kTiers;
}

namespace {

Json OptionalJson(const std::optional<double>& v) { return v.has_value() ? Json(*v) : Json(nullptr); }

std::optional<double> Finite(double v) { return std::isfinite(v) ? std::optional<double>(v) : std::nullopt; }

// A required number, or null; errors name `where` and the key.
Result<std::optional<double>> OptionalNumber(const Json& j, const std::string& where, const char* key) {
  const auto it = j.find(key);
  if (it == j.end()) return Status::Error(where + "." + key + ": missing required field (a number or null)");
  if (it->is_null()) return std::optional<double>();
  if (!it->is_number())
    return Status::Error(where + "." + key + ": expected a number or null, got " + JsonTypeDescription(*it));
  const double v = it->get<double>();
  if (!std::isfinite(v)) return Status::Error(where + "." + key + ": non-finite number");
  return std::optional<double>(v);
}

Result<double> RequiredNumber(const Json& j, const std::string& where, const char* key) {
  ICEF_ASSIGN_OR_RETURN(const std::optional<double> v, OptionalNumber(j, where, key));
  if (!v) return Status::Error(where + "." + key + ": expected a number, got null");
  return *v;
}

std::string OptionalString(const Json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}

std::string Fmt(const std::optional<double>& v, const char* format) {
  if (!v) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, format, *v);
  return buf;
}

}  // namespace

std::span<const MetricField> MetricFields() {
  static const MetricField kFields[] = {
      {"psnr", &FrameMetrics::psnr, &TierMetrics::psnr, true},
      {"ssim", &FrameMetrics::ssim, &TierMetrics::ssim, true},
      {"lpips", &FrameMetrics::lpips, &TierMetrics::lpips, true},
      {"id_cosine", &FrameMetrics::id_cosine, &TierMetrics::id_cosine, true},
      {"id_distance", &FrameMetrics::id_distance, &TierMetrics::id_distance, true},
      {"id_distance_gt", &FrameMetrics::id_distance_gt, &TierMetrics::id_distance_gt, true},
      {"id_distance_reference", &FrameMetrics::id_distance_reference, &TierMetrics::id_distance_reference,
       false},
      {"id_excess", &FrameMetrics::id_excess, &TierMetrics::id_excess, false},
      {"expr_gain", &FrameMetrics::expr_gain, &TierMetrics::expr_gain, false},
      {"expr_corr", &FrameMetrics::expr_corr, &TierMetrics::expr_corr, false},
      {"expr_gain_coarse", &FrameMetrics::expr_gain_coarse, &TierMetrics::expr_gain_coarse, false},
      {"region_psnr", &FrameMetrics::region_psnr, &TierMetrics::region_psnr, false},
      {"psnr_neutral_floor", &FrameMetrics::psnr_neutral_floor, &TierMetrics::psnr_neutral_floor, false},
      {"face_detail", &FrameMetrics::face_detail, &TierMetrics::face_detail, false},
  };
  return kFields;
}

namespace {

// One optional metric read from `j` into `*out`: a required one must be there (a number or null),
// an optional one may be absent.
Status ReadMetric(const Json& j, const std::string& where, const char* key, bool required,
                  std::optional<double>* out) {
  if (!required && !j.contains(key)) return Status::Ok();
  ICEF_ASSIGN_OR_RETURN(*out, OptionalNumber(j, where, key));
  return Status::Ok();
}

}  // namespace

Json FrameMetrics::ToJson() const {
  Json j;
  j["file_path"] = file_path;
  j["tier"] = TierName(tier);
  j["delta"] = delta;
  for (const MetricField& f : MetricFields()) j[f.key] = OptionalJson(this->*f.frame);
  j["expr_true_rms"] = OptionalJson(expr_true_rms);
  j["nearest_index"] = nearest_index;
  j["model_delta"] = model_delta;
  j["kappa"] = kappa;
  j["landmarks"] = landmarks;
  j["neutral_landmarks"] = neutral_landmarks;
  j["render"] = render_path;
  return j;
}

Result<FrameMetrics> FrameMetrics::FromJson(const Json& j, const std::string& where) {
  if (!j.is_object()) return Status::Error(where + ": expected an object, got " + JsonTypeDescription(j));
  FrameMetrics f;
  const auto path = j.find("file_path");
  if (path == j.end() || !path->is_string()) return Status::Error(where + ".file_path: expected a string");
  f.file_path = path->get<std::string>();
  const auto tier = j.find("tier");
  if (tier == j.end() || !tier->is_string()) return Status::Error(where + ".tier: expected a string");
  const std::optional<Tier> parsed = ParseTier(tier->get<std::string>());
  if (!parsed)
    return Status::Error(where + ".tier: unknown tier '" + tier->get<std::string>() +
                         "' (expected observed, near, moderate or far)");
  f.tier = *parsed;
  ICEF_ASSIGN_OR_RETURN(f.delta, RequiredNumber(j, where, "delta"));
  for (const MetricField& field : MetricFields())
    ICEF_RETURN_IF_ERROR(ReadMetric(j, where, field.key, field.required, &(f.*field.frame)));
  ICEF_RETURN_IF_ERROR(ReadMetric(j, where, "expr_true_rms", false, &f.expr_true_rms));
  if (j.contains("nearest_index") && j["nearest_index"].is_number_integer())
    f.nearest_index = j["nearest_index"].get<int>();
  if (j.contains("model_delta") && j["model_delta"].is_number())
    f.model_delta = j["model_delta"].get<double>();
  if (j.contains("kappa") && j["kappa"].is_number()) f.kappa = j["kappa"].get<double>();
  f.landmarks = OptionalString(j, "landmarks");
  f.neutral_landmarks = OptionalString(j, "neutral_landmarks");
  f.render_path = OptionalString(j, "render");
  return f;
}

Json TierMetrics::ToJson() const {
  Json j;
  j["count"] = count;
  for (const MetricField& f : MetricFields()) j[f.key] = OptionalJson(this->*f.tier);
  j["id_share_under_0_6"] = OptionalJson(id_share_under_0_6);
  j["expr_count"] = expr_count;
  j["expr_negligible"] = expr_negligible;
  j["id_count"] = id_count;
  j["mean_delta"] = mean_delta;
  return j;
}

Result<TierMetrics> TierMetrics::FromJson(const Json& j, const std::string& where) {
  if (!j.is_object()) return Status::Error(where + ": expected an object, got " + JsonTypeDescription(j));
  TierMetrics t;
  ICEF_ASSIGN_OR_RETURN(const double count, RequiredNumber(j, where, "count"));
  if (count < 0 || count != std::floor(count)) return Status::Error(where + ".count: expected a count");
  t.count = static_cast<int>(count);
  for (const MetricField& field : MetricFields())
    ICEF_RETURN_IF_ERROR(ReadMetric(j, where, field.key, field.required, &(t.*field.tier)));
  ICEF_RETURN_IF_ERROR(ReadMetric(j, where, "id_share_under_0_6", true, &t.id_share_under_0_6));
  if (j.contains("expr_count") && j["expr_count"].is_number_integer())
    t.expr_count = j["expr_count"].get<int>();
  if (j.contains("expr_negligible") && j["expr_negligible"].is_number_integer())
    t.expr_negligible = j["expr_negligible"].get<int>();
  if (j.contains("id_count") && j["id_count"].is_number_integer()) t.id_count = j["id_count"].get<int>();
  if (j.contains("mean_delta") && j["mean_delta"].is_number()) t.mean_delta = j["mean_delta"].get<double>();
  return t;
}

std::array<TierMetrics, kNumTiers> AggregateTiers(const std::vector<FrameMetrics>& frames) {
  struct Acc {
    double sum = 0;
    int n = 0;
    void Add(const std::optional<double>& v) {
      if (v) sum += *v, ++n;
    }
    std::optional<double> Mean() const { return n > 0 ? std::optional<double>(sum / n) : std::nullopt; }
  };
  const std::span<const MetricField> fields = MetricFields();
  struct TierAcc {
    std::vector<Acc> metrics;  // one per MetricFields() entry
    Acc under, delta;
    int negligible = 0, expr_count = 0, id_count = 0;
  };
  std::array<TierAcc, kNumTiers> acc;
  for (TierAcc& a : acc) a.metrics.resize(fields.size());
  std::array<TierMetrics, kNumTiers> out;
  for (const FrameMetrics& f : frames) {
    const int t = TierIndex(f.tier);
    TierAcc& a = acc[t];
    ++out[t].count;
    a.delta.Add(f.delta);
    for (size_t i = 0; i < fields.size(); ++i) a.metrics[i].Add(f.*fields[i].frame);
    a.expr_count += f.expr_gain.has_value();
    a.id_count += f.id_distance.has_value();
    if (f.expr_true_rms && !f.expr_gain) ++a.negligible;
    if (f.id_distance) a.under.Add(*f.id_distance < kSamePersonThreshold ? 1.0 : 0.0);
  }
  for (int t = 0; t < kNumTiers; ++t) {
    const TierAcc& a = acc[t];
    TierMetrics& m = out[t];
    for (size_t i = 0; i < fields.size(); ++i) m.*fields[i].tier = a.metrics[i].Mean();
    m.id_share_under_0_6 = a.under.Mean();
    m.expr_count = a.expr_count;
    m.expr_negligible = a.negligible;
    m.id_count = a.id_count;
    m.mean_delta = a.delta.Mean().value_or(0.0);
  }
  return out;
}

Json TrainFrameFit::ToJson() const {
  Json j;
  j["file_path"] = file_path;
  j["face_psnr"] = OptionalJson(face_psnr);
  j["face_pixels"] = face_pixels;
  j["face_detail"] = OptionalJson(face_detail);
  j["psnr"] = OptionalJson(psnr);
  j["render"] = render_path;
  return j;
}

Result<TrainFrameFit> TrainFrameFit::FromJson(const Json& j, const std::string& where) {
  if (!j.is_object()) return Status::Error(where + ": expected an object, got " + JsonTypeDescription(j));
  TrainFrameFit f;
  const auto path = j.find("file_path");
  if (path == j.end() || !path->is_string()) return Status::Error(where + ".file_path: expected a string");
  f.file_path = path->get<std::string>();
  ICEF_ASSIGN_OR_RETURN(f.face_psnr, OptionalNumber(j, where, "face_psnr"));
  ICEF_ASSIGN_OR_RETURN(f.psnr, OptionalNumber(j, where, "psnr"));
  if (j.contains("face_pixels") && j["face_pixels"].is_number_integer())
    f.face_pixels = j["face_pixels"].get<int>();
  if (j.contains("face_detail")) {
    ICEF_ASSIGN_OR_RETURN(f.face_detail, OptionalNumber(j, where, "face_detail"));
  }
  f.render_path = OptionalString(j, "render");
  return f;
}

TrainingFit TrainingFit::Of(std::vector<TrainFrameFit> frames) {
  TrainingFit fit;
  fit.count = static_cast<int>(frames.size());
  double face_sum = 0, psnr_sum = 0, detail_sum = 0;
  int psnr_n = 0, detail_n = 0;
  for (const TrainFrameFit& f : frames) {
    if (f.face_detail) detail_sum += *f.face_detail, ++detail_n;
    if (f.face_psnr) {
      face_sum += *f.face_psnr, ++fit.face_count;
      fit.face_psnr_min = std::min(fit.face_psnr_min.value_or(*f.face_psnr), *f.face_psnr);
    }
    if (f.psnr) psnr_sum += *f.psnr, ++psnr_n;
  }
  if (fit.face_count > 0) fit.face_psnr = face_sum / fit.face_count;
  if (psnr_n > 0) fit.psnr = psnr_sum / psnr_n;
  if (detail_n > 0) fit.face_detail = detail_sum / detail_n;
  fit.frames = std::move(frames);
  return fit;
}

Json TrainingFit::ToJson() const {
  Json j;
  j["count"] = count;
  j["face_count"] = face_count;
  j["face_psnr"] = OptionalJson(face_psnr);
  j["face_psnr_min"] = OptionalJson(face_psnr_min);
  j["psnr"] = OptionalJson(psnr);
  j["face_detail"] = OptionalJson(face_detail);
  Json frames_json = Json::array();
  for (const TrainFrameFit& f : frames) frames_json.push_back(f.ToJson());
  j["frames"] = std::move(frames_json);
  return j;
}

Result<TrainingFit> TrainingFit::FromJson(const Json& j, const std::string& where) {
  if (!j.is_object()) return Status::Error(where + ": expected an object, got " + JsonTypeDescription(j));
  TrainingFit fit;
  ICEF_ASSIGN_OR_RETURN(const double count, RequiredNumber(j, where, "count"));
  if (count < 0 || count != std::floor(count)) return Status::Error(where + ".count: expected a count");
  fit.count = static_cast<int>(count);
  if (j.contains("face_count") && j["face_count"].is_number_integer())
    fit.face_count = j["face_count"].get<int>();
  ICEF_ASSIGN_OR_RETURN(fit.face_psnr, OptionalNumber(j, where, "face_psnr"));
  ICEF_ASSIGN_OR_RETURN(fit.face_psnr_min, OptionalNumber(j, where, "face_psnr_min"));
  ICEF_ASSIGN_OR_RETURN(fit.psnr, OptionalNumber(j, where, "psnr"));
  if (j.contains("face_detail")) {
    ICEF_ASSIGN_OR_RETURN(fit.face_detail, OptionalNumber(j, where, "face_detail"));
  }
  const auto frames = j.find("frames");
  if (frames == j.end() || !frames->is_array()) return Status::Error(where + ".frames: expected an array");
  for (size_t i = 0; i < frames->size(); ++i) {
    ICEF_ASSIGN_OR_RETURN(
        TrainFrameFit f, TrainFrameFit::FromJson((*frames)[i], where + ".frames[" + std::to_string(i) + "]"));
    fit.frames.push_back(std::move(f));
  }
  return fit;
}

std::string TrainingFit::Summary() const {
  if (count == 0) return "training-view fit: unavailable (no training frame rendered)";
  const std::string all = std::to_string(count) + " views";
  if (!face_psnr)
    return "training-view fit: face-region PSNR unavailable (no landmarks_2d), full image " +
           Fmt(psnr, "%.2f") + " dB (" + all + ")";
  const std::string views = face_count == count ? all : std::to_string(face_count) + " of " + all;
  return "training-view fit: face-region PSNR " + Fmt(face_psnr, "%.2f") + " dB (worst " +
         Fmt(face_psnr_min, "%.2f") + ", " + views + "), full image " + Fmt(psnr, "%.2f") +
         " dB, face detail " + Fmt(face_detail, "%.2f") + " x the truth's";
}

Json EvalResult::ToJson() const {
  Json j;
  j["method"] = method;
  j["expression_scale"] = expression_scale;
  j["identity_available"] = identity_available;
  if (!identity_note.empty()) j["identity_note"] = identity_note;
  j["lpips_available"] = lpips_available;
  j["identity_missing"] = identity_missing;
  Json frames_json = Json::array();
  for (const FrameMetrics& f : frames) frames_json.push_back(f.ToJson());
  j["frames"] = std::move(frames_json);
  Json tiers_json = Json::object();
  for (Tier t : AllTiers()) tiers_json[TierName(t)] = tiers[TierIndex(t)].ToJson();
  j["tiers"] = std::move(tiers_json);
  j["train_fit"] = train_fit.ToJson();
  return j;
}

Result<EvalResult> EvalResult::FromJson(const Json& j, const std::string& origin) {
  if (!j.is_object()) return Status::Error(origin + ": expected a JSON object");
  EvalResult r;
  const auto method = j.find("method");
  if (method == j.end() || !method->is_string()) return Status::Error(origin + ": method: expected a string");
  r.method = method->get<std::string>();
  if (j.contains("expression_scale") && j["expression_scale"].is_number())
    r.expression_scale = j["expression_scale"].get<double>();
  if (j.contains("identity_available") && j["identity_available"].is_boolean())
    r.identity_available = j["identity_available"].get<bool>();
  if (j.contains("lpips_available") && j["lpips_available"].is_boolean())
    r.lpips_available = j["lpips_available"].get<bool>();
  if (j.contains("identity_missing") && j["identity_missing"].is_number_integer())
    r.identity_missing = j["identity_missing"].get<int>();
  r.identity_note = OptionalString(j, "identity_note");
  const auto frames = j.find("frames");
  if (frames == j.end() || !frames->is_array()) return Status::Error(origin + ": frames: expected an array");
  for (size_t i = 0; i < frames->size(); ++i) {
    ICEF_ASSIGN_OR_RETURN(
        FrameMetrics f, FrameMetrics::FromJson((*frames)[i], origin + ": frames[" + std::to_string(i) + "]"));
    r.frames.push_back(std::move(f));
  }
  const auto tiers = j.find("tiers");
  if (tiers == j.end() || !tiers->is_object()) return Status::Error(origin + ": tiers: expected an object");
  for (Tier t : AllTiers()) {
    const auto it = tiers->find(TierName(t));
    if (it == tiers->end()) return Status::Error(origin + ": tiers." + TierName(t) + ": missing");
    ICEF_ASSIGN_OR_RETURN(r.tiers[TierIndex(t)],
                          TierMetrics::FromJson(*it, origin + ": tiers." + std::string(TierName(t))));
  }
  // Metrics files from before the training-view fit have none: it stays empty.
  if (const auto fit = j.find("train_fit"); fit != j.end() && !fit->is_null()) {
    ICEF_ASSIGN_OR_RETURN(r.train_fit, TrainingFit::FromJson(*fit, origin + ": train_fit"));
  }
  return r;
}

std::string EvalResult::Table() const {
  std::ostringstream s;
  char line[256];
  if (expression_scale != 1) s << "every frame rendered at " << expression_scale << " x its expression\n";
  std::snprintf(line, sizeof line, "%-9s %5s %7s %7s %6s %6s %9s %9s %11s %10s %9s %11s\n", "tier", "count",
                "psnr", "floor", "ssim", "lpips", "expr_gain", "expr_corr", "expr_coarse", "region_psnr",
                "expr_n", "face_detail");
  s << line;
  for (Tier t : AllTiers()) {
    const TierMetrics& m = tiers[TierIndex(t)];
    const std::string expr_n =
        std::to_string(m.expr_count) + (m.expr_negligible ? "+" + std::to_string(m.expr_negligible) : "");
    std::snprintf(line, sizeof line, "%-9s %5d %7s %7s %6s %6s %9s %9s %11s %10s %9s %11s\n", TierName(t),
                  m.count, Fmt(m.psnr, "%.2f").c_str(), Fmt(m.psnr_neutral_floor, "%.2f").c_str(),
                  Fmt(m.ssim, "%.3f").c_str(), Fmt(m.lpips, "%.3f").c_str(), Fmt(m.expr_gain, "%.3f").c_str(),
                  Fmt(m.expr_corr, "%.3f").c_str(), Fmt(m.expr_gain_coarse, "%.3f").c_str(),
                  Fmt(m.region_psnr, "%.2f").c_str(), expr_n.c_str(), Fmt(m.face_detail, "%.2f").c_str());
    s << line;
  }
  std::snprintf(line, sizeof line, "%-9s %9s %7s %10s %7s %9s %7s\n", "tier", "id_cosine", "id_dist",
                "id_dist_gt", "gt_ref", "id_excess", "id<0.6");
  s << line;
  for (Tier t : AllTiers()) {
    const TierMetrics& m = tiers[TierIndex(t)];
    std::snprintf(line, sizeof line, "%-9s %9s %7s %10s %7s %9s %7s\n", TierName(t),
                  Fmt(m.id_cosine, "%.4f").c_str(), Fmt(m.id_distance, "%.3f").c_str(),
                  Fmt(m.id_distance_gt, "%.3f").c_str(), Fmt(m.id_distance_reference, "%.3f").c_str(),
                  Fmt(m.id_excess, "%+.3f").c_str(),
                  m.id_share_under_0_6 ? Fmt(100.0 * *m.id_share_under_0_6, "%.0f%%").c_str() : "-");
    s << line;
  }
  s << "floor: PSNR of the ground-truth neutral against the ground truth (a model that renders no "
       "expression); "
       "expr_gain: share of the true change (ground truth - its neutral) that the render's change (render - "
       "the "
       "model's neutral) reproduces in the brow/eye/mouth region (1 = all, 0 = none), expr_corr their "
       "cosine, "
       "expr_coarse the same share with both changes low-passed (2 px at 128): a soft render that has the "
       "expression scores high here and lower on pixels; "
       "expr_n: frames in those means (+ frames left out: negligible true change)\n";
  s << "id_*: face-descriptor distance/cosine of each render to the model's own neutral render (same view); "
       "id_dist_gt: to the ground truth; gt_ref: the ground truth's own distance to its neutral; "
       "id_excess = id_dist - gt_ref (negative: the render moves less than the truth)\n";
  s << train_fit.Summary() << "\n";
  if (!lpips_available) s << "lpips: unavailable (no weights file given; see docs/evaluation.md)\n";
  if (!identity_available)
    s << "identity: unavailable" << (identity_note.empty() ? "" : " (" + identity_note + ")") << "\n";
  else if (identity_missing > 0)
    s << "identity: no face found in " << identity_missing << " of " << frames.size()
      << " frames (null there)\n";
  return s.str();
}

Status WriteMetricsFile(const fs::path& path, const EvalResult& result) {
  return WriteFileAtomic(path, FormatJson(result.ToJson()));
}

Result<EvalResult> ReadMetricsFile(const fs::path& path) {
  ICEF_ASSIGN_OR_RETURN(const Json j, ReadJsonFile(path));
  return EvalResult::FromJson(j, path.string());
}

Status EvalOptions::Validate() const {
  if (!std::isfinite(expression_scale))
    return Status::Error("expression_scale: must be a finite number, got " +
                         std::to_string(expression_scale));
  if (train_fit_frames < 0)
    return Status::Error("train_fit_frames: must be >= 0, got " + std::to_string(train_fit_frames));
  return Status::Ok();
}

std::string EvalOptions::ToString() const {
  return "EvalOptions(out_dir=" + out_dir.string() +
         ", write_neutral_renders=" + (write_neutral_renders ? "true" : "false") +
         ", expression_scale=" + std::to_string(expression_scale) +
         ", occupancy=" + (occupancy == RenderOccupancyMode::kExpression ? "expression" : "training") +
         ", train_fit_frames=" + std::to_string(train_fit_frames) + ")";
}

namespace {

// One test view: the model's neutral render and its descriptor (computed once per view), and the
// ground-truth neutral with its landmarks when the dataset has them.
struct NeutralView {
  int index = 0;
  Image render;
  std::optional<Image> truth;                         // ground-truth neutral, composited
  std::optional<std::vector<Vec2f>> truth_landmarks;  // its 68 landmarks (dataset)
  std::optional<FaceDescriptor> descriptor;
  std::optional<FaceDescriptor> gt_descriptor;  // of the ground-truth neutral, same landmarks
  std::string landmarks = "none";
  std::string render_path;
};

// Frames of the same view share a neutral render: keyed by the neutral file when the dataset names
// one, else by the exact camera.
std::string ViewKey(const Frame& frame) {
  if (frame.neutral_file_path) return "file:" + *frame.neutral_file_path;
  std::ostringstream s;
  s.precision(17);
  const Intrinsics& k = frame.camera.intrinsics();
  s << "cam:" << k.width << ' ' << k.height << ' ' << k.fl_x << ' ' << k.fl_y << ' ' << k.cx << ' ' << k.cy;
  const Mat4d& m = frame.camera.world_from_cam();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) s << ' ' << m(r, c);
  return s.str();
}

// The 68 landmarks of the frame's neutral image: the frame's neutral_landmarks_2d, else those of a
// dataset frame whose image is the neutral image (any split), if any.
std::optional<std::vector<Vec2f>> NeutralLandmarksOf(const Dataset& dataset, const Frame& frame) {
  if (frame.neutral_landmarks_2d) return frame.neutral_landmarks_2d;
  if (!frame.neutral_file_path) return std::nullopt;
  for (const auto* split : {&dataset.train, &dataset.test, &dataset.val})
    for (const Frame& f : *split)
      if (f.file_path == *frame.neutral_file_path && f.landmarks_2d) return f.landmarks_2d;
  return std::nullopt;
}

std::optional<FaceDescriptor> TryDescribe(FaceIdentity& identity, const Image& image,
                                          const std::optional<std::vector<Vec2f>>& landmarks) {
  Result<FaceIdentityResult> r = identity.Describe(image, landmarks);
  if (!r.ok()) return std::nullopt;
  return r->descriptor;
}

// The model's neutral render of the frame's view, the ground-truth neutral and their identity
// descriptors. Landmarks of the neutral: from the dataset, else detected on the neutral ground
// truth, else the frame's own, else detected on the neutral render.
Result<NeutralView> MakeNeutralView(const AvatarModel& model, const Dataset& dataset, const Frame& frame,
                                    int index, const EvalOptions& options, const EvalNetworks& networks,
                                    const Executor& executor) {
  NeutralView view;
  view.index = index;
  const std::vector<float> neutral_beta(dataset.expression_dim, 0.f);
  view.render =
      RenderImage(model, frame.camera, neutral_beta, dataset.background, executor, options.occupancy).color;
  if (!options.out_dir.empty() && options.write_neutral_renders) {
    char name[64];
    std::snprintf(name, sizeof name, "renders/neutral_%03d.png", view.index);
    view.render_path = name;
    ICEF_RETURN_IF_ERROR(WritePng(options.out_dir / view.render_path, view.render));
  }
  if (frame.neutral_file_path) {
    ICEF_ASSIGN_OR_RETURN(const Image read, ReadImage(dataset.root / *frame.neutral_file_path));
    view.truth = CompositeOver(read, dataset.background);
    view.truth_landmarks = NeutralLandmarksOf(dataset, frame);
  }
  if (!networks.identity) return view;
  std::optional<std::vector<Vec2f>> lm = view.truth_landmarks;
  if (lm) {
    view.landmarks = "dataset";
  } else if (view.truth) {
    Result<FaceIdentityResult> d = networks.identity->Describe(*view.truth, std::nullopt);
    if (d.ok()) lm = d->landmarks, view.landmarks = "detector (ground truth)";
  }
  if (!lm && frame.landmarks_2d) lm = frame.landmarks_2d, view.landmarks = "frame";
  if (lm) {
    view.descriptor = TryDescribe(*networks.identity, view.render, lm);
    if (view.truth) view.gt_descriptor = TryDescribe(*networks.identity, *view.truth, lm);
  } else {
    view.descriptor = TryDescribe(*networks.identity, view.render, std::nullopt);
    if (view.descriptor) view.landmarks = "detector (render)";
  }
  if (!view.descriptor) view.landmarks = "none";
  return view;
}

// Expression fidelity, region PSNR and the neutral floor of one frame (eval/expression_fidelity.h).
Status MeasureExpressionMetrics(const Frame& frame, const Image& render, const Image& truth,
                                const NeutralView& view, FrameMetrics* m) {
  if (view.truth) {
    ICEF_ASSIGN_OR_RETURN(const double floor, Psnr(*view.truth, truth));
    m->psnr_neutral_floor = Finite(floor);
  }
  if (!frame.landmarks_2d) return Status::Ok();
  const Image region = ExpressionRegion(truth.width, truth.height, *frame.landmarks_2d,
                                        view.truth_landmarks.value_or(std::vector<Vec2f>()),
                                        DefaultRegionDilation(truth.width));
  Result<double> region_psnr = Psnr(render, truth, &region);
  if (!region_psnr.ok()) return Status::Ok();  // the region lies outside the image: no values
  m->region_psnr = Finite(*region_psnr);
  if (!view.truth) return Status::Ok();
  ICEF_ASSIGN_OR_RETURN(
      const ExpressionFidelity f,
      MeasureExpression(render, view.render, truth, *view.truth, region, DefaultCoarseSigma(truth.width)));
  m->expr_true_rms = f.true_rms;
  m->expr_gain = f.gain;
  m->expr_corr = f.corr;
  m->expr_gain_coarse = f.gain_coarse;
  return Status::Ok();
}

std::string RenderName(const std::string& file_path, const std::string& prefix = "") {
  return "renders/" + prefix + fs::path(file_path).stem().string() + ".png";
}

// The frame's image composited over the background; errors: unreadable, or not the camera's size.
Result<Image> LoadTruth(const Dataset& dataset, const Frame& frame, const std::string& where) {
  ICEF_ASSIGN_OR_RETURN(const Image raw, LoadFrameImage(dataset, frame));
  Image gt = CompositeOver(raw, dataset.background);
  if (gt.width != frame.camera.width() || gt.height != frame.camera.height())
    return Status::Error(where + ": image is " + std::to_string(gt.width) + "x" + std::to_string(gt.height) +
                         ", camera says " + std::to_string(frame.camera.width()) + "x" +
                         std::to_string(frame.camera.height()));
  return gt;
}

std::vector<float> ScaledExpression(const Frame& frame, double scale) {
  std::vector<float> beta = frame.expression;
  for (float& v : beta) v = static_cast<float>(scale * v);
  return beta;
}

// [a | b] (RGB; same height), for comparing a render with its truth.
Image SideBySide(const Image& a, const Image& b) {
  Image out(a.width + b.width, std::max(a.height, b.height), 3, 1.f);
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      for (int c = 0; c < 3; ++c) out.At(x, y, c) = a.Rgb(x, y)[c];
  for (int y = 0; y < b.height; ++y)
    for (int x = 0; x < b.width; ++x)
      for (int c = 0; c < 3; ++c) out.At(a.width + x, y, c) = b.Rgb(x, y)[c];
  return out;
}

// Indices of up to `max_count` of `n` items, evenly spaced, ascending (all of them when n <= max_count).
std::vector<size_t> EvenlySpaced(size_t n, int max_count) {
  const size_t m = std::min(n, static_cast<size_t>(std::max(max_count, 0)));
  std::vector<size_t> out(m);
  for (size_t i = 0; i < m; ++i) out[i] = i * n / m;
  return out;
}

// The training-view fit of one training frame: full-image PSNR, and PSNR inside the face region
// (the hull of its landmarks) when it has landmarks.
Result<TrainFrameFit> MeasureTrainFrame(const Frame& frame, const Image& render, const Image& truth) {
  TrainFrameFit f;
  f.file_path = frame.file_path;
  ICEF_ASSIGN_OR_RETURN(const double psnr, Psnr(render, truth));
  f.psnr = Finite(psnr);
  if (!frame.landmarks_2d) return f;
  const Image face = FaceRegion(truth.width, truth.height, *frame.landmarks_2d);
  for (float v : face.pixels) f.face_pixels += v > 0.5f;
  if (f.face_pixels == 0) return f;
  ICEF_ASSIGN_OR_RETURN(const double face_psnr, Psnr(render, truth, &face));
  f.face_psnr = Finite(face_psnr);
  Result<double> detail = DetailRatio(render, truth, &face);
  if (detail.ok()) f.face_detail = Finite(*detail);
  return f;
}

}  // namespace

namespace {

// The image metrics of one test frame against its truth: PSNR, SSIM, face detail, LPIPS.
Status MeasureImage(const Frame& frame, const Image& render, const Image& gt, const EvalNetworks& networks,
                    FrameMetrics* m) {
  ICEF_ASSIGN_OR_RETURN(const double psnr, Psnr(render, gt));
  m->psnr = Finite(psnr);
  ICEF_ASSIGN_OR_RETURN(const double ssim, Ssim(render, gt));
  m->ssim = Finite(ssim);
  if (frame.landmarks_2d) {
    const Image face = FaceRegion(gt.width, gt.height, *frame.landmarks_2d);
    Result<double> detail = DetailRatio(render, gt, &face);
    if (detail.ok()) m->face_detail = Finite(*detail);
  }
  if (networks.lpips) {
    ICEF_ASSIGN_OR_RETURN(const double lpips, networks.lpips->Distance(render, gt));
    m->lpips = Finite(lpips);
  }
  return Status::Ok();
}

// The identity metrics of one test frame: the render against the model's own neutral render, against
// the truth, and the truth's own drift. False when no face could be aligned on the render.
bool MeasureIdentity(FaceIdentity& identity, const Frame& frame, const Image& render, const Image& gt,
                     const NeutralView& view, FrameMetrics* m) {
  m->landmarks = frame.landmarks_2d ? "dataset" : "detector";
  const std::optional<FaceDescriptor> render_desc = TryDescribe(identity, render, frame.landmarks_2d);
  const std::optional<FaceDescriptor> gt_desc = TryDescribe(identity, gt, frame.landmarks_2d);
  if (!render_desc) m->landmarks = "none";
  if (render_desc && view.descriptor) {
    m->id_distance = DescriptorDistance(*render_desc, *view.descriptor);
    m->id_cosine = DescriptorCosine(*render_desc, *view.descriptor);
  }
  if (render_desc && gt_desc) m->id_distance_gt = DescriptorDistance(*render_desc, *gt_desc);
  if (gt_desc && view.gt_descriptor)
    m->id_distance_reference = DescriptorDistance(*gt_desc, *view.gt_descriptor);
  if (m->id_distance && m->id_distance_reference) m->id_excess = *m->id_distance - *m->id_distance_reference;
  return m->id_distance.has_value();
}

// Everything the protocol measures on test frame i; `views` caches the model's neutral render per view.
Result<FrameMetrics> MeasureTestFrame(const AvatarModel& model, const Dataset& dataset, size_t i,
                                      const EvalOptions& options, const EvalNetworks& networks,
                                      const Executor& executor, std::map<std::string, NeutralView>* views,
                                      int* identity_missing) {
  const Frame& frame = dataset.test[i];
  const std::string where =
      dataset.root.string() + ": test frame " + std::to_string(i) + " (" + frame.file_path + ")";
  ICEF_ASSIGN_OR_RETURN(const Image gt, LoadTruth(dataset, frame, where));
  const RenderedImage render =
      RenderImage(model, frame.camera, ScaledExpression(frame, options.expression_scale), dataset.background,
                  executor, options.occupancy);
  FrameMetrics m;
  m.file_path = frame.file_path;
  m.delta = frame.delta.value_or(render.nearest.delta);
  // Frames without a tier get one from their delta and the dataset's thresholds (or synth's defaults).
  const std::array<double, 2> thresholds = dataset.tier_thresholds.value_or(
      std::array<double, 2>{synth::SynthOptions().near_threshold, synth::SynthOptions().far_threshold});
  m.tier = frame.tier.value_or(synth::TierForDelta(m.delta, thresholds[0], thresholds[1]));
  m.nearest_index = render.nearest.index;
  m.model_delta = render.nearest.delta;
  m.kappa = render.nearest.kappa;
  ICEF_RETURN_IF_ERROR(MeasureImage(frame, render.color, gt, networks, &m));
  if (!options.out_dir.empty()) {
    m.render_path = RenderName(frame.file_path);
    ICEF_RETURN_IF_ERROR(WritePng(options.out_dir / m.render_path, render.color));
  }
  // The model's neutral render of this view (once per view).
  auto it = views->find(ViewKey(frame));
  if (it == views->end()) {
    Result<NeutralView> view =
        MakeNeutralView(model, dataset, frame, static_cast<int>(views->size()), options, networks, executor);
    if (!view.ok()) return view.status().WithContext(where);
    it = views->emplace(ViewKey(frame), std::move(*view)).first;
  }
  m.neutral_landmarks = it->second.landmarks;
  ICEF_RETURN_IF_ERROR(MeasureExpressionMetrics(frame, render.color, gt, it->second, &m).WithContext(where));
  m.landmarks = "none";
  if (networks.identity && !MeasureIdentity(*networks.identity, frame, render.color, gt, it->second, &m))
    ++*identity_missing;
  return m;
}

// The training-view fit: training frames rendered back exactly as the test frames.
Result<TrainingFit> MeasureTrainingFit(const AvatarModel& model, const Dataset& dataset,
                                       const EvalOptions& options, const Executor& executor,
                                       ProgressBar* progress) {
  const std::vector<size_t> fit_indices = EvenlySpaced(dataset.train.size(), options.train_fit_frames);
  std::vector<TrainFrameFit> fits;
  for (size_t n = 0; n < fit_indices.size(); ++n) {
    const Frame& frame = dataset.train[fit_indices[n]];
    const std::string where = dataset.root.string() + ": training frame " + std::to_string(fit_indices[n]) +
                              " (" + frame.file_path + ")";
    if (progress)
      progress->Update(static_cast<int64_t>(dataset.test.size()),
                       "training view " + std::to_string(n + 1) + "/" + std::to_string(fit_indices.size()));
    ICEF_ASSIGN_OR_RETURN(const Image gt, LoadTruth(dataset, frame, where));
    const RenderedImage render =
        RenderImage(model, frame.camera, ScaledExpression(frame, options.expression_scale),
                    dataset.background, executor, options.occupancy);
    Result<TrainFrameFit> fit = MeasureTrainFrame(frame, render.color, gt);
    if (!fit.ok()) return fit.status().WithContext(where);
    if (!options.out_dir.empty()) {
      fit->render_path = RenderName(frame.file_path, "fit_");
      ICEF_RETURN_IF_ERROR(WritePng(options.out_dir / fit->render_path, render.color));
      // The truth and the render side by side, to look at what the numbers say.
      const std::string pair = fs::path(fit->render_path).replace_extension().string() + "_vs_truth.png";
      ICEF_RETURN_IF_ERROR(WritePng(options.out_dir / pair, SideBySide(gt, render.color)));
    }
    fits.push_back(std::move(*fit));
  }
  return TrainingFit::Of(std::move(fits));
}

}  // namespace

Result<EvalResult> EvaluateModel(const AvatarModel& model, const Dataset& dataset, const EvalOptions& options,
                                 const EvalNetworks& networks, const Executor& executor,
                                 ProgressBar* progress) {
  ICEF_RETURN_IF_ERROR(options.Validate());
  if (dataset.test.empty()) return Status::Error(dataset.root.string() + ": the dataset has no test frames");
  if (dataset.expression_dim != model.setup().expression_dim)
    return Status::Error(dataset.root.string() + ": expression_dim " +
                         std::to_string(dataset.expression_dim) + " does not match the model's " +
                         std::to_string(model.setup().expression_dim));
  if (!options.out_dir.empty()) {
    std::error_code ec;
    fs::create_directories(options.out_dir / "renders", ec);
    if (ec)
      return Status::Error((options.out_dir / "renders").string() +
                           ": cannot create directory: " + ec.message());
  }
  EvalResult result;
  result.method = MethodName(model.method());
  result.expression_scale = options.expression_scale;
  result.identity_available = networks.identity != nullptr;
  result.identity_note = networks.identity ? "" : networks.identity_note;
  result.lpips_available = networks.lpips != nullptr;
  std::map<std::string, NeutralView> views;
  for (size_t i = 0; i < dataset.test.size(); ++i) {
    ICEF_ASSIGN_OR_RETURN(FrameMetrics m, MeasureTestFrame(model, dataset, i, options, networks, executor,
                                                           &views, &result.identity_missing));
    result.frames.push_back(std::move(m));
    if (progress) {
      const FrameMetrics& last = result.frames.back();
      progress->Update(static_cast<int64_t>(i) + 1,
                       std::string(TierName(last.tier)) + " psnr " + Fmt(last.psnr, "%.2f") + " gain " +
                           Fmt(last.expr_gain, "%.2f") + " id " + Fmt(last.id_distance, "%.3f"));
    }
  }
  result.tiers = AggregateTiers(result.frames);
  ICEF_ASSIGN_OR_RETURN(result.train_fit, MeasureTrainingFit(model, dataset, options, executor, progress));
  if (progress) progress->Finish();
  return result;
}

}  // namespace icef::eval
