#include "icef/synth/photo_set.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "icef/core/rng.h"
#include "icef/face/expression.h"
#include "icef/face/face_model.h"
#include "icef/face/style_gap.h"
#include "icef/io/atomic_file.h"
#include "icef/synth/head_model.h"
#include "icef/synth/noise.h"
#include "icef/synth/synthesize.h"

namespace icef::synth {

namespace fs = std::filesystem;

namespace {

// Head width over head height used to check that the largest head fits across the image
// (cranium with ears ~0.6 head units wide over ~0.73 tall, plus a margin for yaw and roll).
constexpr double kHeadAspect = 0.9;

std::string Num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

// Crown and chin heights of the head's axis (head frame, neutral), from the face geometry.
struct HeadSpan {
  double crown_y, chin_y;
  double Height() const { return crown_y - chin_y; }
  Vec3d Centre() const { return Vec3d(0.0, 0.5 * (crown_y + chin_y), 0.0); }
};
HeadSpan SpanOf(const face::ShapeParams& shape) {
  const face::FaceGeometry g = face::FaceGeometry::FromShape(shape);
  return {double(g.cranium_c.y() + g.cranium_r.y()), double(g.chin_c.y() - g.chin_r.y())};
}

Mat3d AxisRotation(const Vec3d& axis, double deg) {
  return Eigen::AngleAxisd(deg * M_PI / 180.0, axis).toRotationMatrix();
}

}  // namespace

Status PhotoSetOptions::Validate() const {
  if (num_photos < 1 || num_photos > 100000)
    return Status::Error("num_photos: expected 1..100000, got " + std::to_string(num_photos));
  if (width < 16 || width > 8192 || height < 16 || height > 8192)
    return Status::Error("width x height: expected 16..8192 pixels each, got " + std::to_string(width) + "x" +
                         std::to_string(height));
  if (!(focal_scale > 0.1 && focal_scale < 100.0))
    return Status::Error("focal_scale: expected 0.1..100, got " + Num(focal_scale));
  if (!(max_yaw_deg >= 0.0 && max_yaw_deg <= 80.0))
    return Status::Error("max_yaw_deg: expected 0..80, got " + Num(max_yaw_deg));
  if (!(max_pitch_deg >= 0.0 && max_pitch_deg <= 60.0))
    return Status::Error("max_pitch_deg: expected 0..60, got " + Num(max_pitch_deg));
  if (!(max_roll_deg >= 0.0 && max_roll_deg <= 90.0))
    return Status::Error("max_roll_deg: expected 0..90, got " + Num(max_roll_deg));
  if (!(min_head_fraction > 0.02 && min_head_fraction <= max_head_fraction && max_head_fraction <= 1.0))
    return Status::Error("head fraction: expected 0.02 < min (" + Num(min_head_fraction) + ") <= max (" +
                         Num(max_head_fraction) + ") <= 1");
  if (!(max_offset_fraction >= 0.0 && max_offset_fraction < 0.5))
    return Status::Error("max_offset_fraction: expected 0..0.5, got " + Num(max_offset_fraction));
  // The largest head at the largest offset must stay inside the image.
  if (0.5 * max_head_fraction + max_offset_fraction > 0.5)
    return Status::Error(
        "max_head_fraction / 2 + max_offset_fraction: expected <= 0.5 (the head must fit "
        "vertically), got " +
        Num(0.5 * max_head_fraction + max_offset_fraction));
  const double head_width_px = kHeadAspect * max_head_fraction * height;
  if (0.5 * head_width_px + max_offset_fraction * width > 0.5 * width)
    return Status::Error("max_head_fraction " + Num(max_head_fraction) + " with max_offset_fraction " +
                         Num(max_offset_fraction) + ": the head (~" + Num(std::round(head_width_px)) +
                         " px wide) would not fit across " + std::to_string(width) + " px");
  if (!(max_expression >= 0.0 && max_expression <= 1.5))
    return Status::Error("max_expression: expected 0..1.5, got " + Num(max_expression));
  return render.Validate().WithContext("render");
}

std::string PhotoSetOptions::ToString() const {
  std::ostringstream os;
  os << "PhotoSetOptions(identity_seed=" << identity_seed
     << ", generic_style=" << (generic_style ? "true" : "false") << ", photos=" << num_photos
     << ", size=" << width << "x" << height << ", focal_scale=" << focal_scale << ", yaw<=" << max_yaw_deg
     << ", pitch<=" << max_pitch_deg << ", roll<=" << max_roll_deg << ", head_fraction=[" << min_head_fraction
     << ", " << max_head_fraction << "], offset<=" << max_offset_fraction
     << ", max_expression=" << max_expression << ", background_seed=" << background_seed << ", "
     << render.ToString() << ")";
  return os.str();
}

Json PhotoSetOptions::ToJson() const {
  Json j = Json::object();
  j["identity_seed"] = identity_seed;
  j["generic_style"] = generic_style;
  j["num_photos"] = num_photos;
  j["width"] = width;
  j["height"] = height;
  j["focal_scale"] = focal_scale;
  j["max_yaw_deg"] = max_yaw_deg;
  j["max_pitch_deg"] = max_pitch_deg;
  j["max_roll_deg"] = max_roll_deg;
  j["min_head_fraction"] = min_head_fraction;
  j["max_head_fraction"] = max_head_fraction;
  j["max_offset_fraction"] = max_offset_fraction;
  j["max_expression"] = max_expression;
  j["background_seed"] = background_seed;
  j["render"] = Json{{"supersample", render.supersample},
                     {"light_direction", Json::array({JsonFloat(render.light_direction.x()),
                                                      JsonFloat(render.light_direction.y()),
                                                      JsonFloat(render.light_direction.z())})},
                     {"ambient", JsonFloat(render.ambient)},
                     {"diffuse", JsonFloat(render.diffuse)},
                     {"max_steps", render.max_steps}};
  return j;
}

std::string SynthPhoto::ToString() const {
  std::ostringstream os;
  os << "SynthPhoto(" << image.width << "x" << image.height << ", yaw=" << yaw_deg << ", pitch=" << pitch_deg
     << ", roll=" << roll_deg << ", head_fraction=" << head_fraction << ", expression={";
  const char* sep = "";
  for (int e = 0; e < face::kNumExpressions && e < static_cast<int>(expression.size()); ++e)
    if (expression[e] != 0.f) os << sep << face::kExpressionNames[e] << "=" << expression[e], sep = ", ";
  os << "})";
  return os.str();
}

IdentityParams PhotoSetIdentity(const PhotoSetOptions& options) {
  IdentityParams identity = IdentityParams::FromSeed(options.identity_seed);
  if (options.generic_style) identity.style = face::ExpressionStyle::Generic();
  return identity;
}

Result<std::vector<PhotoPlan>> PlanPhotoSet(const PhotoSetOptions& o) {
  ICEF_RETURN_IF_ERROR(o.Validate());
  const IdentityParams identity = PhotoSetIdentity(o);
  const HeadSpan span = SpanOf(identity.shape);
  const Vec3d centre = span.Centre();
  const Aabb bounds = face::FaceModel(identity.shape, identity.style).Bounds();
  Intrinsics in;
  in.width = o.width;
  in.height = o.height;
  in.fl_x = in.fl_y = o.focal_scale * std::max(o.width, o.height);
  in.cx = 0.5 * o.width;
  in.cy = 0.5 * o.height;

  std::vector<PhotoPlan> plans;
  for (int i = 0; i < o.num_photos; ++i) {
    Rng rng(o.identity_seed, StreamId("synth.photos"), 0, i);
    PhotoPlan p;
    p.yaw_deg = rng.Uniform(-o.max_yaw_deg, o.max_yaw_deg);
    p.pitch_deg = rng.Uniform(-o.max_pitch_deg, o.max_pitch_deg);
    p.roll_deg = rng.Uniform(-o.max_roll_deg, o.max_roll_deg);
    p.head_fraction = rng.Uniform(o.min_head_fraction, o.max_head_fraction);
    p.offset_px = Vec2d(rng.Uniform(-1.0, 1.0) * o.max_offset_fraction * o.width,
                        rng.Uniform(-1.0, 1.0) * o.max_offset_fraction * o.height);
    // cam_from_head: rotation R and the head centre at (X, Y, -d) in the camera frame.
    const Mat3d r = AxisRotation(Vec3d::UnitZ(), p.roll_deg) * AxisRotation(Vec3d::UnitY(), p.yaw_deg) *
                    AxisRotation(Vec3d::UnitX(), -p.pitch_deg);
    const double d = in.fl_y * span.Height() / (p.head_fraction * o.height);
    const Vec3d centre_cam(d / in.fl_x * p.offset_px.x(), -d / in.fl_y * p.offset_px.y(), -d);
    Mat4d world_from_cam = Mat4d::Identity();
    world_from_cam.block<3, 3>(0, 0) = r.transpose();
    world_from_cam.block<3, 1>(0, 3) = centre - r.transpose() * centre_cam;
    p.camera = Camera(in, world_from_cam);
    Aabb clearance = bounds;
    clearance.min.array() -= 0.1f;
    clearance.max.array() += 0.1f;
    if (clearance.Contains(p.camera.Center().cast<float>()))
      return Status::Error("photo " + std::to_string(i) + ": the camera (distance " + Num(d) +
                           ") would sit inside the head's box: raise focal_scale or lower max_head_fraction");
    // Expression: photo 0 neutral, the others 1-3 active expressions in [0.1, 1] * max_expression.
    p.expression.assign(face::kNumExpressions, 0.f);
    if (i > 0) {
      Rng er(o.identity_seed, StreamId("synth.photo_expression"), 0, i);
      const int active = 1 + static_cast<int>(er.Below(3));
      for (int a = 0; a < active; ++a)
        p.expression[er.Below(face::kNumExpressions)] =
            static_cast<float>(er.Uniform(0.1, 1.0) * o.max_expression);
    }
    plans.push_back(std::move(p));
  }
  return plans;
}

namespace {

Vec3f HsvToRgb(float h, float s, float v) {
  const float hh = 6.f * (h - std::floor(h));
  const int sector = static_cast<int>(hh) % 6;
  const float f = hh - std::floor(hh);
  const float p = v * (1.f - s), q = v * (1.f - s * f), t = v * (1.f - s * (1.f - f));
  switch (sector) {
    case 0:
      return {v, t, p};
    case 1:
      return {q, v, p};
    case 2:
      return {p, v, t};
    case 3:
      return {p, q, v};
    case 4:
      return {t, p, v};
    default:
      return {v, p, q};
  }
}

float SmoothStep(float e0, float e1, float x) {
  const float t = std::clamp((x - e0) / (e1 - e0), 0.f, 1.f);
  return t * t * (3.f - 2.f * t);
}

}  // namespace

Image PhotoBackground(uint64_t seed, int index, int width, int height, const Executor& executor) {
  Rng rng(seed, StreamId("synth.photo_background"), 0, static_cast<uint64_t>(index));
  // Five colours: two base regions, a third region, stripes, blobs.
  std::array<Vec3f, 5> colors;
  for (Vec3f& c : colors)
    c = HsvToRgb(rng.Uniform(), static_cast<float>(rng.Uniform(0.25, 0.85)),
                 static_cast<float>(rng.Uniform(0.2, 0.95)));
  std::array<uint32_t, 6> seeds;
  for (uint32_t& s : seeds) s = rng.NextU32();
  const float base_freq = static_cast<float>(rng.Uniform(2.0, 5.0));
  const float region_freq = static_cast<float>(rng.Uniform(1.5, 3.5));
  const double stripe_angle = rng.Uniform(0.0, M_PI);
  const Vec2f stripe_dir(static_cast<float>(std::cos(stripe_angle)),
                         static_cast<float>(std::sin(stripe_angle)));
  const float stripe_period = static_cast<float>(rng.Uniform(0.025, 0.09));  // fraction of the height
  const float stripe_warp = static_cast<float>(rng.Uniform(0.2, 1.2));
  const float blob_freq = static_cast<float>(rng.Uniform(3.0, 8.0));
  const float blob_density = static_cast<float>(rng.Uniform(0.3, 0.8));
  const Vec2f light_dir =
      Vec2f(static_cast<float>(rng.Normal()), static_cast<float>(rng.Normal())).normalized();

  Image image(width, height, 3);
  ParallelForChunks(executor, height, 8, [&](int64_t row_begin, int64_t row_end) {
    for (int y = static_cast<int>(row_begin); y < row_end; ++y) {
      for (int x = 0; x < width; ++x) {
        // Coordinates in units of the image height (the pattern scales with the image).
        const Vec2f q((x + 0.5f) / height, (y + 0.5f) / height);
        const float n_base = FractalNoise(Vec3f(q.x() * base_freq, q.y() * base_freq, 0.37f), seeds[0], 4);
        Vec3f c = colors[0] + (colors[1] - colors[0]) * SmoothStep(-0.25f, 0.25f, n_base);
        const float n_region =
            FractalNoise(Vec3f(q.x() * region_freq, q.y() * region_freq, 1.7f), seeds[1], 3);
        c += (colors[2] - c) * SmoothStep(0.15f, 0.3f, n_region);
        // Warped stripes inside a noise-shaped region.
        const float warp = stripe_warp * FractalNoise(Vec3f(q.x() * 3.f, q.y() * 3.f, 2.9f), seeds[2], 3);
        const float phase = (q.dot(stripe_dir) / stripe_period + warp) * 2.f * static_cast<float>(M_PI);
        const float stripe = SmoothStep(-0.2f, 0.2f, std::sin(phase));
        const float stripe_region =
            SmoothStep(-0.05f, 0.15f, FractalNoise(Vec3f(q.x() * 2.f, q.y() * 2.f, 4.1f), seeds[3], 2));
        c += (colors[3] - c) * (stripe * stripe_region);
        // Blobs.
        const float blob =
            CellSpots(Vec3f(q.x(), q.y(), 0.5f / blob_freq), blob_freq, blob_density, seeds[4]);
        c += (colors[4] - c) * blob;
        // A soft lighting gradient and fine grain.
        const float shade = 0.85f + 0.25f * (q - Vec2f(0.5f * width / height, 0.5f)).dot(light_dir);
        const float grain = 0.03f * ValueNoise(Vec3f(x * 0.7f, y * 0.7f, 0.f), seeds[5]);
        for (int ch = 0; ch < 3; ++ch) image.At(x, y, ch) = std::clamp(c[ch] * shade + grain, 0.f, 1.f);
      }
    }
  });
  return image;
}

Result<std::vector<SynthPhoto>> RenderPhotoSet(const PhotoSetOptions& options, const Executor& executor) {
  ICEF_ASSIGN_OR_RETURN(const std::vector<PhotoPlan> plans, PlanPhotoSet(options));
  const HeadModel head(PhotoSetIdentity(options));
  const uint64_t background_seed = options.background_seed != 0
                                       ? options.background_seed
                                       : Mix64(options.identity_seed ^ StreamId("synth.photo_bg_seed"));
  std::vector<SynthPhoto> photos;
  for (int i = 0; i < static_cast<int>(plans.size()); ++i) {
    const PhotoPlan& plan = plans[i];
    SynthPhoto photo;
    photo.camera = plan.camera;
    photo.expression = plan.expression;
    photo.yaw_deg = plan.yaw_deg;
    photo.pitch_deg = plan.pitch_deg;
    photo.roll_deg = plan.roll_deg;
    photo.head_fraction = plan.head_fraction;
    const Image rgba = RenderGroundTruth(head, plan.camera, plan.expression, executor, options.render);
    photo.image = PhotoBackground(background_seed, i, options.width, options.height, executor);
    photo.alpha = Image(options.width, options.height, 1);
    // RenderGroundTruth's RGB is the covered samples' mean colour (not premultiplied).
    for (int y = 0; y < options.height; ++y) {
      for (int x = 0; x < options.width; ++x) {
        const float a = rgba.At(x, y, 3);
        photo.alpha.At(x, y, 0) = a;
        for (int c = 0; c < 3; ++c)
          photo.image.At(x, y, c) = a * rgba.At(x, y, c) + (1.f - a) * photo.image.At(x, y, c);
      }
    }
    const LandmarkView lv = ProjectLandmarks(head, plan.camera, plan.expression);
    photo.landmarks_2d = lv.landmarks_2d;
    photo.landmarks_visible = lv.visible;
    photo.landmarks_3d = lv.landmarks_3d;
    photos.push_back(std::move(photo));
  }
  return photos;
}

namespace {

std::string PhotoFile(const char* dir_and_prefix, int i) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s_%03d.png", dir_and_prefix, i);
  return buf;
}

template <typename Vec>
Json Points(const std::vector<Vec>& points) {
  Json a = Json::array();
  for (const Vec& p : points) {
    Json row = Json::array();
    for (int k = 0; k < p.size(); ++k) row.push_back(JsonFloat(p[k]));
    a.push_back(std::move(row));
  }
  return a;
}

}  // namespace

Json PhotoSetTruthJson(const PhotoSetOptions& options, const std::vector<SynthPhoto>& photos) {
  Json doc = Json::object();
  doc["note"] =
      "Synthetic photos with known truth (icef synth --photos; src/icef/synth/photo_set.h). camera_to_head "
      "maps camera coordinates (OpenGL/NeRF convention: looks down -z, +y up) to the head frame (+y up, the "
      "face looks down +z, head ~0.75 units tall). landmarks_2d are iBUG-68 in pixels with pixel centres at "
      "+0.5; landmarks_3d are in the head frame. Head pose: cam_from_head = Rz(roll) Ry(yaw) Rx(-pitch).";
  doc["options"] = options.ToJson();
  doc["style_file"] = kStyleInfoFile;
  doc["expression_names"] = face::ExpressionNames();
  // The identity's true shape scales (kShapeParamNames order), for judging a tracker's shape fit.
  Json shape = Json::object();
  const std::array<float, face::ShapeParams::kCount> scales = PhotoSetIdentity(options).shape.ToArray();
  for (int i = 0; i < face::ShapeParams::kCount; ++i) shape[face::kShapeParamNames[i]] = JsonFloat(scales[i]);
  doc["shape"] = std::move(shape);
  Json list = Json::array();
  for (int i = 0; i < static_cast<int>(photos.size()); ++i) {
    const SynthPhoto& p = photos[i];
    const Intrinsics& in = p.camera.intrinsics();
    Json j = Json::object();
    j["file"] = PhotoFile("photos/photo", i);
    j["alpha_file"] = PhotoFile("truth/alpha", i);
    j["width"] = in.width;
    j["height"] = in.height;
    j["fl_x"] = in.fl_x;
    j["fl_y"] = in.fl_y;
    j["cx"] = in.cx;
    j["cy"] = in.cy;
    Json m = Json::array();
    for (int r = 0; r < 4; ++r) {
      Json row = Json::array();
      for (int c = 0; c < 4; ++c) row.push_back(p.camera.world_from_cam()(r, c));
      m.push_back(std::move(row));
    }
    j["camera_to_head"] = std::move(m);
    j["head_pose_deg"] = Json{{"yaw", p.yaw_deg}, {"pitch", p.pitch_deg}, {"roll", p.roll_deg}};
    j["head_fraction"] = p.head_fraction;
    Json expression = Json::object();
    for (int e = 0; e < face::kNumExpressions && e < static_cast<int>(p.expression.size()); ++e)
      expression[face::kExpressionNames[e]] = JsonFloat(p.expression[e]);
    j["expression"] = std::move(expression);
    j["landmarks_2d"] = Points(p.landmarks_2d);
    Json visible = Json::array();
    for (bool b : p.landmarks_visible) visible.push_back(b);
    j["landmarks_visible"] = std::move(visible);
    j["landmarks_3d"] = Points(p.landmarks_3d);
    list.push_back(std::move(j));
  }
  doc["photos"] = std::move(list);
  return doc;
}

Status WritePhotoSet(const PhotoSetOptions& options, const std::vector<SynthPhoto>& photos,
                     const fs::path& out_dir) {
  ICEF_RETURN_IF_ERROR(options.Validate());
  for (const fs::path& dir : {out_dir / "photos", out_dir / "truth"}) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) return Status::Error(dir.string() + ": cannot create directory: " + ec.message());
  }
  for (int i = 0; i < static_cast<int>(photos.size()); ++i) {
    const SynthPhoto& p = photos[i];
    if (p.image.channels != 3 || p.alpha.channels != 1)
      return Status::Error("photo " + std::to_string(i) + ": expected an RGB image and a 1-channel alpha");
    ICEF_RETURN_IF_ERROR(WritePng(out_dir / PhotoFile("photos/photo", i), p.image));
    ICEF_RETURN_IF_ERROR(WritePng(out_dir / PhotoFile("truth/alpha", i), p.alpha));
  }
  ICEF_RETURN_IF_ERROR(
      WriteFileAtomic(out_dir / kPhotoTruthFile, FormatJson(PhotoSetTruthJson(options, photos))));
  // The subject's style, as SynthesizeDataset writes it.
  const IdentityParams identity = PhotoSetIdentity(options);
  SynthOptions synth_options;
  synth_options.identity_seed = options.identity_seed;
  synth_options.generic_style = options.generic_style;
  const face::StyleGap gap = face::MeasureStyleGap(identity.shape, identity.style);
  return WriteFileAtomic(out_dir / kStyleInfoFile, FormatJson(StyleInfoJson(synth_options, identity, gap)));
}

}  // namespace icef::synth
