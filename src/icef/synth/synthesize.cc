#include "icef/synth/synthesize.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "icef/core/rng.h"
#include "icef/face/expression.h"
#include "icef/face/face_model.h"
#include "icef/io/atomic_file.h"
#include "icef/synth/head_model.h"

namespace icef::synth {

namespace fs = std::filesystem;

SceneAxes SceneAxes::All() {
  SceneAxes a;
  a.skin = a.lighting = a.placement = a.camera = a.views = a.resolution = a.detail = true;
  return a;
}

bool SceneAxes::Any() const {
  return skin || lighting || placement || camera || views || resolution || detail;
}

const std::vector<std::string>& SceneAxes::Names() {
  static const std::vector<std::string> kNames = {"skin",  "lighting",   "placement", "camera",
                                                  "views", "resolution", "detail"};
  return kNames;
}

namespace {
bool* AxisField(SceneAxes& a, const std::string& name) {
  bool* fields[] = {&a.skin, &a.lighting, &a.placement, &a.camera, &a.views, &a.resolution, &a.detail};
  const auto& names = SceneAxes::Names();
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return fields[i];
  return nullptr;
}
}  // namespace

Status SceneAxes::Set(const std::string& name, bool value) {
  bool* field = AxisField(*this, name);
  if (!field) {
    std::string known;
    for (const std::string& n : Names()) known += (known.empty() ? "" : ", ") + n;
    return Status::Error("unknown scene axis '" + name + "' (expected one of " + known + ")");
  }
  *field = value;
  return Status::Ok();
}

std::string SceneAxes::ToString() const {
  std::string out;
  SceneAxes copy = *this;
  for (const std::string& n : Names())
    if (*AxisField(copy, n)) out += (out.empty() ? "" : ",") + n;
  return out.empty() ? "none" : out;
}

Status SynthOptions::Validate() const {
  if (out_dir.empty()) return Status::Error("out_dir: required");
  if (num_train < 1 || num_train > 1000)
    return Status::Error("k: expected 1..1000 training frames, got " + std::to_string(num_train));
  if (resolution < 8 || resolution > 4096)
    return Status::Error("res: expected 8..4096 pixels, got " + std::to_string(resolution));
  if (test_views < 1 || test_views > 1000)
    return Status::Error("test_views: expected 1..1000, got " + std::to_string(test_views));
  if (novel_per_tier < 0 || novel_per_tier > 1000)
    return Status::Error("novel_per_tier: expected 0..1000, got " + std::to_string(novel_per_tier));
  if (!(near_threshold > 0.0) || !(far_threshold > near_threshold))
    return Status::Error("tier thresholds: expected 0 < near (" + std::to_string(near_threshold) +
                         ") < far (" + std::to_string(far_threshold) + ")");
  if (far_threshold > 2.5)
    return Status::Error(
        "far threshold: expected <= 2.5 (far expressions are drawn up to ~1.5 per parameter), got " +
        std::to_string(far_threshold));
  if (!(camera_distance > 1.5))
    return Status::Error("camera_distance: expected > 1.5 (outside the head's box), got " +
                         std::to_string(camera_distance));
  if (!(focal_scale > 0.1))
    return Status::Error("focal_scale: expected > 0.1, got " + std::to_string(focal_scale));
  if (!(max_yaw_deg >= 0.0 && max_yaw_deg <= 80.0)) return Status::Error("max_yaw_deg: expected 0..80");
  if (!(max_pitch_deg >= 0.0 && max_pitch_deg <= 60.0)) return Status::Error("max_pitch_deg: expected 0..60");
  if (!(max_drawn_resolution >= 128 && max_drawn_resolution <= 4096))
    return Status::Error("max_drawn_resolution: expected 128..4096, got " +
                         std::to_string(max_drawn_resolution));
  if (!(head_scale >= 0.25 && head_scale <= 4.0))
    return Status::Error("head_scale: expected 0.25..4, got " + std::to_string(head_scale));
  if (!head_offset.allFinite()) return Status::Error("head_offset: expected finite values");
  const Aabb head = face::FaceModel(face::ShapeParams()).Bounds();
  for (int a = 0; a < 3; ++a) {
    const double lo = head_scale * head.min[a] + head_offset[a],
                 hi = head_scale * head.max[a] + head_offset[a];
    if (lo < -1.0 || hi > 1.0)
      return Status::Error("head_scale/head_offset: the head (axis " + std::to_string(a) + ": " +
                           std::to_string(lo) + ".." + std::to_string(hi) +
                           ") leaves the dataset's box [-1, 1]");
  }
  return render.Validate().WithContext("render");
}

std::string SynthOptions::ToString() const {
  std::ostringstream os;
  os << "SynthOptions(out=" << out_dir.string() << ", identity_seed=" << identity_seed
     << ", generic_style=" << (generic_style ? "true" : "false") << ", k=" << num_train
     << ", res=" << resolution << ", test_views=" << test_views << ", novel_per_tier=" << novel_per_tier
     << ", thresholds=[" << near_threshold << ", " << far_threshold << "], distance=" << camera_distance
     << ", focal_scale=" << focal_scale << ", yaw<=" << max_yaw_deg << ", pitch<=" << max_pitch_deg << ", ";
  if (vary.Any()) os << "vary=" << vary.ToString() << " (max_res " << max_drawn_resolution << "), ";
  if (head_scale != 1.0 || !head_offset.isZero())
    os << "head_scale=" << head_scale << ", head_offset=[" << head_offset.transpose() << "], ";
  os << render.ToString() << ")";
  return os.str();
}

SynthOptions ResolveScene(const SynthOptions& options) {
  SynthOptions o = options;
  const uint64_t seed = o.identity_seed;
  if (o.vary.lighting) {
    Rng rng(seed, StreamId("synth.scene.lighting"));
    // Key light anywhere over the front, from 70 degrees left to right and from slightly below
    // to high above; strength and ambient (the fill ratio) vary independently.
    const double azimuth = (-70.0 + 140.0 * SpreadUnit(seed, 0.7182818285, rng)) * M_PI / 180.0,
                 elevation = rng.Uniform(-10.0, 60.0) * M_PI / 180.0;
    o.render.light_direction = Vec3f(static_cast<float>(std::sin(azimuth) * std::cos(elevation)),
                                     static_cast<float>(std::sin(elevation)),
                                     static_cast<float>(std::cos(azimuth) * std::cos(elevation)));
    o.render.diffuse = static_cast<float>(rng.Uniform(0.5, 0.95));
    o.render.ambient = static_cast<float>(rng.Uniform(0.12, 0.45));
    // A second light on the other side (a fill or, from behind, a rim) for half the subjects.
    if (rng.UniformDouble() < 0.5) {
      const double a2 = -std::copysign(1.0, azimuth) * rng.Uniform(40.0, 130.0) * M_PI / 180.0;
      const double e2 = rng.Uniform(-10.0, 40.0) * M_PI / 180.0;
      o.render.fill_direction =
          Vec3f(static_cast<float>(std::sin(a2) * std::cos(e2)), static_cast<float>(std::sin(e2)),
                static_cast<float>(std::cos(a2) * std::cos(e2)));
      o.render.fill = static_cast<float>(rng.Uniform(0.1, 0.4));
    }
    o.render.specular = static_cast<float>(rng.Uniform(0.0, 0.14));
    o.render.shininess = static_cast<float>(rng.Uniform(12.0, 48.0));
  }
  if (o.vary.placement) {
    // Scale 0.75-1.2, and an offset anywhere the head still fits the box with a 0.03 margin.
    Rng rng(seed, StreamId("synth.scene.placement"));
    o.head_scale = 0.75 + 0.45 * SpreadUnit(seed, 0.4142135624, rng);
    const Aabb head = face::FaceModel(face::ShapeParams()).Bounds();
    for (int a = 0; a < 3; ++a) {
      const double lo = -0.97 - o.head_scale * head.min[a], hi = 0.97 - o.head_scale * head.max[a];
      o.head_offset[a] = lo < hi ? rng.Uniform(lo, hi) : 0.5 * (lo + hi);
    }
  }
  if (o.vary.camera) {
    // Distance 2.8-6 head units; the focal length puts the head at 50-85 % of the image height
    // (the classic 3.5 / 3.6 is ~80 %).
    Rng rng(seed, StreamId("synth.scene.camera"));
    o.camera_distance = rng.Uniform(2.8, 6.0);
    o.focal_scale =
        3.6 * (o.camera_distance / 3.5) * ((0.5 + 0.35 * SpreadUnit(seed, 0.7320508076, rng)) / 0.8);
  }
  if (o.vary.views) {
    Rng rng(seed, StreamId("synth.scene.views"));
    o.max_yaw_deg = 15.0 + 30.0 * SpreadUnit(seed, 0.2360679775, rng);
    o.max_pitch_deg = rng.Uniform(5.0, 20.0);
  }
  if (o.vary.resolution) {
    Rng rng(seed, StreamId("synth.scene.resolution"));
    std::vector<int> sizes;
    for (int r : {128, 160, 192, 256, 320, 384, 448, 512})
      if (r <= o.max_drawn_resolution) sizes.push_back(r);
    o.resolution = sizes[rng.Below(sizes.size())];
  }
  return o;
}

IdentityParams SynthIdentity(const SynthOptions& options) {
  IdentityParams identity = IdentityParams::FromSeed(options.identity_seed);
  if (options.generic_style) identity.style = face::ExpressionStyle::Generic();
  if (options.vary.skin) DrawDiverseSkin(options.identity_seed, &identity);
  if (options.vary.detail) DrawFineDetail(options.identity_seed, &identity);
  return identity;
}

Json SceneInfoJson(const SynthOptions& o, const IdentityParams& id) {
  auto vec = [](const auto& v) {
    Json a = Json::array();
    for (int i = 0; i < 3; ++i) a.push_back(static_cast<double>(v[i]));
    return a;
  };
  Json doc = Json::object();
  doc["note"] = "The scene of this synthetic dataset (icef synth; not part of the dataset format).";
  doc["identity_seed"] = o.identity_seed;
  doc["drawn_axes"] = o.vary.ToString();
  doc["lighting"] = Json{{"key_direction", vec(o.render.light_direction)},
                         {"key", o.render.diffuse},
                         {"ambient", o.render.ambient},
                         {"fill_direction", vec(o.render.fill_direction)},
                         {"fill", o.render.fill},
                         {"specular", o.render.specular},
                         {"shininess", o.render.shininess},
                         {"canonical_shading", o.render.canonical_shading}};
  doc["placement"] = Json{{"head_scale", o.head_scale}, {"head_offset", vec(o.head_offset)}};
  doc["camera"] = Json{{"distance", o.camera_distance}, {"focal_scale", o.focal_scale}};
  doc["views"] = Json{{"max_yaw_deg", o.max_yaw_deg}, {"max_pitch_deg", o.max_pitch_deg}};
  doc["resolution"] = o.resolution;
  doc["skin"] = Json{{"skin_tone", vec(id.skin_tone)},
                     {"lip_color", vec(id.lip_color)},
                     {"brow_color", vec(id.brow_color)},
                     {"hair_color", vec(id.hair_color)}};
  doc["detail"] = Json{{"pore_strength", id.pore_strength},
                       {"pore_scale", id.pore_scale},
                       {"wrinkle_strength", id.wrinkle_strength},
                       {"stubble_density", id.stubble_density}};
  return doc;
}

Camera WorldFromHead(const SynthOptions& options, const Camera& head_camera) {
  Mat4d m = head_camera.world_from_cam();
  m.block<3, 1>(0, 3) = options.head_scale * m.block<3, 1>(0, 3) + options.head_offset;
  return Camera(head_camera.intrinsics(), m);
}

Json StyleInfoJson(const SynthOptions& options, const IdentityParams& identity, const face::StyleGap& gap) {
  const face::ExpressionStyle& st = identity.style;
  auto pair = [](const std::array<float, 2>& v) { return Json::array({JsonFloat(v[0]), JsonFloat(v[1])}); };
  Json style = Json::object();
  style["jaw_gain"] = JsonFloat(st.jaw_gain);
  style["jaw_hinge_dy"] = JsonFloat(st.jaw_hinge_dy);
  style["jaw_hinge_dz"] = JsonFloat(st.jaw_hinge_dz);
  style["smile_gain"] = pair(st.smile_gain);
  style["smile_width"] = JsonFloat(st.smile_width);
  style["smile_lift"] = JsonFloat(st.smile_lift);
  style["smile_corner_shift"] = JsonFloat(st.smile_corner_shift);
  style["lip_pucker_gain"] = JsonFloat(st.lip_pucker_gain);
  style["lip_press_gain"] = JsonFloat(st.lip_press_gain);
  style["brow_raise_gain"] = pair(st.brow_raise_gain);
  style["brow_raise_shift"] = JsonFloat(st.brow_raise_shift);
  style["brow_furrow_gain"] = JsonFloat(st.brow_furrow_gain);
  style["eye_close_gain"] = pair(st.eye_close_gain);
  style["cheek_puff_gain"] = JsonFloat(st.cheek_puff_gain);
  Json per_expression = Json::object();
  for (int e = 0; e < face::kNumExpressions; ++e)
    per_expression[face::kExpressionNames[e]] =
        std::isnan(gap.per_expression[e]) ? Json(nullptr) : Json(gap.per_expression[e]);
  Json doc = Json::object();
  doc["note"] =
      "The ground truth's expression style and its landmark gap to the generic face model "
      "(docs/face_model.md). Not part of the dataset: training and evaluation never read it. "
      "Paired values are [right, left] (the subject's own sides).";
  doc["identity_seed"] = options.identity_seed;
  doc["generic_style"] = identity.style.IsGeneric();
  doc["style"] = std::move(style);
  doc["style_gap"] = Json{{"weight", 1.0},
                          {"mean", gap.mean},
                          {"num_measured", gap.num_measured},
                          {"per_expression", std::move(per_expression)}};
  return doc;
}

double ExpressionDelta(const std::vector<float>& beta, const std::vector<std::vector<float>>& train) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : train) {
    double sum = 0.0;
    for (size_t i = 0; i < beta.size(); ++i) sum += (double(beta[i]) - t[i]) * (double(beta[i]) - t[i]);
    best = std::min(best, std::sqrt(sum));
  }
  return best;
}

Tier TierForDelta(double delta, double near_threshold, double far_threshold) {
  if (delta == 0.0) return Tier::kObserved;
  if (delta <= near_threshold) return Tier::kNear;
  if (delta <= far_threshold) return Tier::kModerate;
  return Tier::kFar;
}

Camera OrbitCamera(const Intrinsics& intrinsics, double distance, double yaw_deg, double pitch_deg) {
  const double yaw = yaw_deg * M_PI / 180.0, pitch = pitch_deg * M_PI / 180.0;
  const Vec3d eye(distance * std::sin(yaw) * std::cos(pitch), distance * std::sin(pitch),
                  distance * std::cos(yaw) * std::cos(pitch));
  return Camera::LookAt(intrinsics, eye, Vec3d::Zero());
}

namespace {

double AngleBetweenDeg(const Camera& a, const Camera& b) {
  const Vec3d u = a.Center().normalized(), v = b.Center().normalized();
  return std::acos(std::clamp(u.dot(v), -1.0, 1.0)) * 180.0 / M_PI;
}

// Moderate training expression: 2-4 active parameters in [0.15, 0.65].
std::vector<float> TrainExpression(uint64_t seed, int k) {
  Rng rng(seed, StreamId("synth.train_expression"), 0, k);
  std::vector<float> beta(face::kNumExpressions, 0.f);
  const int active = 2 + static_cast<int>(rng.Below(3));
  for (int a = 0; a < active; ++a)
    beta[rng.Below(face::kNumExpressions)] = static_cast<float>(rng.Uniform(0.15, 0.65));
  return beta;
}

// A candidate novel expression for a tier (the tier of the result is decided from its delta).
std::vector<float> NovelCandidate(Tier tier, const std::vector<std::vector<float>>& train,
                                  const SynthOptions& o, Rng& rng) {
  std::vector<float> beta(face::kNumExpressions, 0.f);
  if (tier == Tier::kFar) {
    // Several parameters pushed to 0.9-1.5 on top of a softened training expression.
    const auto& base = train[rng.Below(train.size())];
    for (int i = 0; i < face::kNumExpressions; ++i) beta[i] = 0.5f * base[i];
    const int active = 3 + static_cast<int>(rng.Below(2));
    for (int a = 0; a < active; ++a)
      beta[rng.Below(face::kNumExpressions)] = static_cast<float>(rng.Uniform(0.9, 1.5));
    return beta;
  }
  // A training expression moved by a step of the tier's length along 2-4 random parameters.
  beta = train[rng.Below(train.size())];
  const double lo = tier == Tier::kNear ? 0.1 * o.near_threshold : o.near_threshold;
  const double hi = tier == Tier::kNear ? o.near_threshold : o.far_threshold;
  std::vector<double> dir(face::kNumExpressions, 0.0);
  const int active = 2 + static_cast<int>(rng.Below(3));
  for (int a = 0; a < active; ++a) dir[rng.Below(face::kNumExpressions)] = rng.Normal();
  double norm = 0.0;
  for (double d : dir) norm += d * d;
  norm = std::sqrt(std::max(norm, 1e-12));
  const double step = rng.Uniform(lo, hi);
  for (int i = 0; i < face::kNumExpressions; ++i)
    beta[i] = static_cast<float>(std::max(0.0, beta[i] + step * dir[i] / norm));
  return beta;
}

}  // namespace

Result<SynthPlan> PlanSynthesis(const SynthOptions& options) {
  ICEF_RETURN_IF_ERROR(options.Validate());
  SynthPlan plan;
  plan.resolved = ResolveScene(options);
  const SynthOptions& o = plan.resolved;
  ICEF_RETURN_IF_ERROR(o.Validate().WithContext("the drawn scene"));
  Intrinsics& in = plan.intrinsics;
  in.width = in.height = o.resolution;
  in.fl_x = in.fl_y = o.focal_scale * o.resolution;
  in.cx = in.cy = 0.5 * o.resolution;
  const uint64_t seed = o.identity_seed;
  // Training views: yaw stratified over [-max_yaw, max_yaw] with jitter, random pitch.
  for (int k = 0; k < o.num_train; ++k) {
    Rng rng(seed, StreamId("synth.train_view"), 0, k);
    const double u = (k + 0.5 + 0.6 * (rng.UniformDouble() - 0.5)) / o.num_train;
    const double yaw = -o.max_yaw_deg + 2.0 * o.max_yaw_deg * u;
    const double pitch = rng.Uniform(-o.max_pitch_deg, o.max_pitch_deg);
    plan.train_cameras.push_back(OrbitCamera(in, o.camera_distance, yaw, pitch));
    plan.train_expressions.push_back(TrainExpression(seed, k));
  }
  // Held-out views: random within 0.9 of the training range, at least 3 degrees from every
  // training view and every other test view where possible.
  for (int v = 0; v < o.test_views; ++v) {
    Camera best;
    double best_gap = -1.0;
    for (int attempt = 0; attempt < 64; ++attempt) {
      Rng rng(seed, StreamId("synth.test_view"), attempt, v);
      const Camera cam = OrbitCamera(in, o.camera_distance, rng.Uniform(-0.9, 0.9) * o.max_yaw_deg,
                                     rng.Uniform(-0.9, 0.9) * o.max_pitch_deg);
      double gap = 1e9;
      for (const Camera& c : plan.train_cameras) gap = std::min(gap, AngleBetweenDeg(cam, c));
      for (const Camera& c : plan.test_cameras) gap = std::min(gap, AngleBetweenDeg(cam, c));
      if (gap > best_gap) best = cam, best_gap = gap;
      if (gap >= 3.0) break;
    }
    plan.test_cameras.push_back(best);
  }
  for (const auto* cameras : {&plan.train_cameras, &plan.test_cameras})
    for (const Camera& c : *cameras)
      if (WorldFromHead(o, c).Center().cwiseAbs().maxCoeff() <= 1.0)
        return Status::Error(
            "camera_distance/head_scale/head_offset: a camera lies inside the dataset's box [-1, 1]^3");
  // Test expressions: every training expression (observed), then novel ones per tier.
  for (const auto& beta : plan.train_expressions)
    plan.test_expressions.push_back({beta, 0.0, Tier::kObserved});
  for (Tier tier : {Tier::kNear, Tier::kModerate, Tier::kFar}) {
    for (int n = 0; n < o.novel_per_tier; ++n) {
      bool found = false;
      for (int attempt = 0; attempt < 500 && !found; ++attempt) {
        Rng rng(seed, StreamId("synth.novel_expression"), static_cast<uint64_t>(tier) * 100000 + attempt, n);
        TestExpression t;
        t.beta = NovelCandidate(tier, plan.train_expressions, o, rng);
        t.delta = ExpressionDelta(t.beta, plan.train_expressions);
        t.tier = TierForDelta(t.delta, o.near_threshold, o.far_threshold);
        if (t.tier != tier || t.delta < 1e-3) continue;
        plan.test_expressions.push_back(t);
        found = true;
      }
      if (!found)
        return Status::Error(std::string("tier thresholds: could not draw a ") + TierName(tier) +
                             " expression with near=" + std::to_string(o.near_threshold) +
                             " far=" + std::to_string(o.far_threshold));
    }
  }
  return plan;
}

namespace {

// A frame seen by `camera` (head frame); its camera and 3D landmarks are stored in the world frame.
Frame MakeFrame(const SynthOptions& o, const HeadModel& head, const Camera& camera,
                const std::vector<float>& beta, std::string file_path) {
  Frame f;
  f.file_path = std::move(file_path);
  f.camera = WorldFromHead(o, camera);
  f.expression = beta;
  const LandmarkView lv = ProjectLandmarks(head, camera, beta);
  f.landmarks_2d = lv.landmarks_2d;
  f.landmarks_2d_visible = lv.visible;
  std::vector<Vec3f> world;
  for (const Vec3f& p : lv.landmarks_3d)
    world.push_back((o.head_scale * p.cast<double>() + o.head_offset).cast<float>());
  f.landmarks_3d = world;
  return f;
}

std::string Numbered(const char* prefix, int i) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "images/%s_%03d.png", prefix, i);
  return buf;
}

}  // namespace

int64_t SynthImageCount(const SynthOptions& o) {
  return o.num_train + o.test_views + int64_t(o.num_train + 3 * o.novel_per_tier) * o.test_views;
}

Status SynthesizeDataset(const SynthOptions& requested, const Executor& executor, ProgressBar* progress,
                         Dataset* written, face::StyleGap* style_gap) {
  ICEF_ASSIGN_OR_RETURN(const SynthPlan plan, PlanSynthesis(requested));
  const SynthOptions& options = plan.resolved;
  std::error_code ec;
  fs::create_directories(options.out_dir / "images", ec);
  if (ec)
    return Status::Error((options.out_dir / "images").string() +
                         ": cannot create directory: " + ec.message());
  const IdentityParams identity = SynthIdentity(options);
  const HeadModel head(identity);
  const face::StyleGap gap = face::MeasureStyleGap(identity.shape, identity.style);

  Dataset ds;
  ds.root = options.out_dir;
  ds.aabb = Aabb();  // [-1, 1]^3
  ds.expression_dim = face::kNumExpressions;
  ds.expression_names = face::ExpressionNames();
  ds.background = options.render.background;
  ds.tier_thresholds = std::array<double, 2>{options.near_threshold, options.far_threshold};

  const int num_views = static_cast<int>(plan.test_cameras.size());
  int64_t done = 0;
  // Renders in the head frame (the ground-truth renderer's), through the camera the frame was made from.
  auto render = [&](Frame frame, const Camera& head_camera) -> Result<Frame> {
    const Image image = RenderGroundTruth(head, head_camera, frame.expression, executor, options.render);
    ICEF_RETURN_IF_ERROR(WritePng(ds.root / frame.file_path, image));
    if (progress) progress->Update(++done, frame.file_path);
    return frame;
  };
  for (int k = 0; k < options.num_train; ++k) {
    ICEF_ASSIGN_OR_RETURN(Frame f, render(MakeFrame(options, head, plan.train_cameras[k],
                                                    plan.train_expressions[k], Numbered("train", k)),
                                          plan.train_cameras[k]));
    ds.train.push_back(std::move(f));
  }
  const std::vector<float> neutral(face::kNumExpressions, 0.f);
  std::vector<Frame> neutral_frames;  // [V]: their landmarks go into the test frames of the view
  for (int v = 0; v < num_views; ++v) {
    ICEF_ASSIGN_OR_RETURN(
        Frame f, render(MakeFrame(options, head, plan.test_cameras[v], neutral, Numbered("test_neutral", v)),
                        plan.test_cameras[v]));
    neutral_frames.push_back(std::move(f));
  }
  int index = 0;
  for (const TestExpression& t : plan.test_expressions) {
    for (int v = 0; v < num_views; ++v) {
      Frame frame = MakeFrame(options, head, plan.test_cameras[v], t.beta, Numbered("test", index++));
      frame.delta = t.delta;
      frame.tier = t.tier;
      frame.neutral_file_path = neutral_frames[v].file_path;
      frame.neutral_landmarks_2d = neutral_frames[v].landmarks_2d;
      frame.neutral_landmarks_3d = neutral_frames[v].landmarks_3d;
      ICEF_ASSIGN_OR_RETURN(Frame f, render(std::move(frame), plan.test_cameras[v]));
      ds.test.push_back(std::move(f));
    }
  }
  ICEF_RETURN_IF_ERROR(SaveDataset(ds));
  ICEF_RETURN_IF_ERROR(
      WriteFileAtomic(options.out_dir / kStyleInfoFile, FormatJson(StyleInfoJson(options, identity, gap))));
  ICEF_RETURN_IF_ERROR(
      WriteFileAtomic(options.out_dir / kSceneInfoFile, FormatJson(SceneInfoJson(options, identity))));
  if (style_gap) *style_gap = gap;
  if (progress)
    progress->Finish(std::to_string(ds.train.size()) + " train, " + std::to_string(ds.test.size()) +
                     " test frames");
  if (written) *written = std::move(ds);
  return Status::Ok();
}

}  // namespace icef::synth
