// LoadDataset: parse and validate transforms_{train,test,val}.json (our format, instant-ngp's
// camera_angle_x, NerFace's intrinsics/expression/bbox/background image).
//
// Focal lengths are signed, and taken as NerFace takes them: its real_to_nerf.py writes
// "intrinsics" [fx, fy, cx, cy] with fx = f_x * -w and fy = f_y * -h (some sequences mix signs
// between frames), and its rays run along ((i - W cx) / fx, -(j - H cy) / fy, -1) in the camera
// frame, so a negative focal length flips that image axis. Our Camera uses the very same formula
// (math/camera.h); every frame's camera goes through Camera::Upright, which turns a frame with
// fl_y < 0 by 180 degrees about its viewing axis and makes both focal lengths change sign, so that
// NerFace's usual fx, fy < 0 become an ordinary camera (positive focal lengths, camera +Y image-up,
// which the face fit relies on) with identical rays. A frame with exactly one negative focal
// length is a mirrored camera; it keeps fl_x < 0 rather than a reflection in transform_matrix, so
// that poses stay rigid everywhere (ValidateRigid on files, saves and checkpoints) and the images,
// landmarks and bboxes are used as stored. The same rule applies to fl_x / fl_y in our format,
// which is how `icef import` writes such a camera. Zero focal lengths are refused.
#include <algorithm>
#include <cmath>

#include "icef/core/parallel.h"
#include "icef/data/dataset.h"
#include "icef/io/json_util.h"

namespace icef {

namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Camera parameters that one level (the file, or one frame) specifies.
struct CameraSpec {
  std::optional<int> w, h;
  std::optional<double> fl_x, fl_y, cx, cy, angle_x, angle_y;
  std::optional<std::array<double, 4>> intrinsics;  // NerFace [fx, fy, cx, cy]
};

Result<CameraSpec> ParseCameraSpec(const JsonObjectView& obj) {
  CameraSpec s;
  for (auto [key, out] : {std::pair{"w", &s.w}, std::pair{"h", &s.h}}) {
    if (!obj.Has(key)) continue;
    ICEF_ASSIGN_OR_RETURN(const int v, obj.Int(key));
    if (v <= 0) return obj.Error(key, "must be a positive image size, got " + std::to_string(v));
    *out = v;
  }
  for (auto [key, out] : {std::pair{"fl_x", &s.fl_x}, std::pair{"fl_y", &s.fl_y}}) {
    if (!obj.Has(key)) continue;
    ICEF_ASSIGN_OR_RETURN(const double v, obj.Number(key));
    if (!(std::isfinite(v) && v != 0))
      return obj.Error(key, "focal length must be a nonzero finite number (negative flips that image axis)");
    *out = v;
  }
  for (auto [key, out] : {std::pair{"cx", &s.cx}, std::pair{"cy", &s.cy}}) {
    if (!obj.Has(key)) continue;
    ICEF_ASSIGN_OR_RETURN(*out, obj.Number(key));
  }
  for (auto [key, out] : {std::pair{"camera_angle_x", &s.angle_x}, std::pair{"camera_angle_y", &s.angle_y}}) {
    if (!obj.Has(key)) continue;
    ICEF_ASSIGN_OR_RETURN(const double v, obj.Number(key));
    if (!(v > 0 && v < kPi)) return obj.Error(key, "field of view must be in (0, pi) radians");
    *out = v;
  }
  if (obj.Has("intrinsics")) {
    ICEF_ASSIGN_OR_RETURN(const std::vector<double> k, obj.NumberArray("intrinsics", 4));
    if (!(std::isfinite(k[0]) && k[0] != 0 && std::isfinite(k[1]) && k[1] != 0))
      return obj.Error(
          "intrinsics",
          "focal lengths [fx, fy] must be nonzero finite numbers (negative flips that image axis)");
    s.intrinsics = std::array<double, 4>{k[0], k[1], k[2], k[3]};
  }
  return s;
}

// The focal lengths and principal point one level determines for a w x h image.
struct PartialIntrinsics {
  std::optional<double> fl_x, fl_y, cx, cy;
};

PartialIntrinsics Resolve(const CameraSpec& s, int w, int h) {
  PartialIntrinsics p;
  if (s.fl_x) {
    p.fl_x = s.fl_x;
  } else if (s.intrinsics) {
    p.fl_x = (*s.intrinsics)[0];
  } else if (s.angle_x) {
    p.fl_x = 0.5 * w / std::tan(0.5 * *s.angle_x);
  }
  if (s.fl_y) {
    p.fl_y = s.fl_y;
  } else if (s.intrinsics) {
    p.fl_y = (*s.intrinsics)[1];
  } else if (s.angle_y) {
    p.fl_y = 0.5 * h / std::tan(0.5 * *s.angle_y);
  } else {
    p.fl_y = p.fl_x;  // square pixels unless told otherwise
  }
  // NerFace stores the principal point as a fraction of the image size and casts rays through
  // integer pixel coordinates; with our pixel centres at +0.5, cx = fraction * w + 0.5 gives the
  // very same rays, whatever the focal lengths' signs (NerFace's i - W cx is our
  // (i + 0.5) - cx). Values above 1 are taken as pixels in our convention, unchanged.
  auto principal = [](double c, int size) { return c <= 1.0 ? c * size + 0.5 : c; };
  if (s.cx) {
    p.cx = s.cx;
  } else if (s.intrinsics) {
    p.cx = principal((*s.intrinsics)[2], w);
  }
  if (s.cy) {
    p.cy = s.cy;
  } else if (s.intrinsics) {
    p.cy = principal((*s.intrinsics)[3], h);
  }
  return p;
}

// What parsing a frame's JSON gives, before its image is looked at.
struct ParsedFrame {
  Frame frame;
  Mat4d world_from_cam;
  CameraSpec camera;
};

// What checking a frame's image(s) on disk gives.
struct ImageCheck {
  Status status;
  std::string file_path;  // resolved (extension added where the JSON omitted it)
  std::optional<std::string> neutral_file_path;
  ImageInfo info;
};

// The existing file for `written` (relative to root): as written, or with an image extension
// appended when the written path has none (NeRF/NerFace convention).
std::optional<std::string> ResolveImageFile(const fs::path& root, const std::string& written) {
  std::error_code ec;
  if (fs::is_regular_file(root / written, ec)) return written;
  if (fs::path(written).has_extension()) return std::nullopt;
  for (const char* ext : {".png", ".jpg", ".jpeg", ".PNG", ".JPG", ".JPEG"})
    if (fs::is_regular_file(root / (written + ext), ec)) return written + ext;
  return std::nullopt;
}

// Resolves and reads the header of the image under `key`; errors name the field.
Result<std::pair<std::string, ImageInfo>> CheckImage(const JsonObjectView& obj, const char* key,
                                                     const fs::path& root, const std::string& written) {
  const std::optional<std::string> resolved = ResolveImageFile(root, written);
  if (!resolved) return obj.Error(key, "image not found: " + (root / written).string());
  Result<ImageInfo> info = ReadImageInfo(root / *resolved);
  if (!info.ok()) return obj.Error(key, info.status().message());
  return std::pair{*resolved, *info};
}

// The 68 landmarks under `key`: 2D (Vec2f) or 3D (Vec3f) points.
template <typename Point>
Result<std::vector<Point>> Landmarks(const JsonObjectView& f, const char* key) {
  ICEF_ASSIGN_OR_RETURN(const auto rows, f.NumberMatrix(key, kNumLandmarks, Point::RowsAtCompileTime));
  std::vector<Point> points;
  for (const auto& row : rows) {
    Point p;
    for (int a = 0; a < Point::RowsAtCompileTime; ++a) p[a] = static_cast<float>(row[a]);
    points.push_back(p);
  }
  return points;
}

Result<ParsedFrame> ParseFrame(const JsonObjectView& f, int expression_dim) {
  ParsedFrame p;
  Frame& frame = p.frame;
  ICEF_ASSIGN_OR_RETURN(frame.file_path, f.String("file_path"));
  if (frame.file_path.empty()) return f.Error("file_path", "must not be empty");

  ICEF_ASSIGN_OR_RETURN(const auto m, f.NumberMatrix("transform_matrix", 4, 4));
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) p.world_from_cam(r, c) = m[r][c];
  if (Status rigid = ValidateRigid(p.world_from_cam); !rigid.ok())
    return f.Error("transform_matrix", rigid.message());
  ICEF_ASSIGN_OR_RETURN(p.camera, ParseCameraSpec(f));

  if (f.Has("expression")) {
    ICEF_ASSIGN_OR_RETURN(const std::vector<double> e, f.NumberArray("expression", expression_dim));
    frame.expression.assign(e.begin(), e.end());
  } else if (expression_dim > 0) {
    return f.Error("expression",
                   "missing required field (expression_dim is " + std::to_string(expression_dim) + ")");
  }

  if (f.Has("landmarks_2d")) {
    ICEF_ASSIGN_OR_RETURN(frame.landmarks_2d, Landmarks<Vec2f>(f, "landmarks_2d"));
  }
  if (f.Has("landmarks_2d_visible")) {
    if (!frame.landmarks_2d) return f.Error("landmarks_2d_visible", "given without landmarks_2d");
    ICEF_ASSIGN_OR_RETURN(frame.landmarks_2d_visible, f.BoolArray("landmarks_2d_visible", kNumLandmarks));
  }
  if (f.Has("landmarks_3d")) {
    ICEF_ASSIGN_OR_RETURN(frame.landmarks_3d, Landmarks<Vec3f>(f, "landmarks_3d"));
  }
  if (f.Has("neutral_landmarks_2d")) {
    ICEF_ASSIGN_OR_RETURN(frame.neutral_landmarks_2d, Landmarks<Vec2f>(f, "neutral_landmarks_2d"));
  }
  if (f.Has("neutral_landmarks_3d")) {
    ICEF_ASSIGN_OR_RETURN(frame.neutral_landmarks_3d, Landmarks<Vec3f>(f, "neutral_landmarks_3d"));
  }
  if (f.Has("delta")) {
    ICEF_ASSIGN_OR_RETURN(const double delta, f.Number("delta"));
    if (delta < 0) return f.Error("delta", "must be >= 0");
    frame.delta = delta;
  }
  if (f.Has("tier")) {
    ICEF_ASSIGN_OR_RETURN(const std::string name, f.String("tier"));
    frame.tier = ParseTier(name);
    if (!frame.tier)
      return f.Error("tier", "unknown tier \"" + name + "\" (expected observed, near, moderate or far)");
  }
  if (f.Has("neutral_file_path")) {
    ICEF_ASSIGN_OR_RETURN(frame.neutral_file_path, f.String("neutral_file_path"));
  }
  if (f.Has("bbox")) {
    ICEF_ASSIGN_OR_RETURN(const std::vector<double> b, f.NumberArray("bbox", 4));
    frame.bbox = std::array<float, 4>{float(b[0]), float(b[1]), float(b[2]), float(b[3])};
  }
  return p;
}

// The file-level fields of one transforms_*.json.
struct SplitHeader {
  std::string file;  // for messages
  CameraSpec camera;
  std::optional<Aabb> aabb;
  std::optional<int> expression_dim;
  std::optional<std::vector<std::string>> expression_names;
  std::optional<Vec3f> background;
  std::optional<std::string> background_file_path;
  std::optional<std::array<double, 2>> tier_thresholds;
  std::vector<JsonObjectView> frames;
};

Result<SplitHeader> ParseHeader(const JsonObjectView& root) {
  SplitHeader h;
  h.file = root.file();
  ICEF_ASSIGN_OR_RETURN(h.camera, ParseCameraSpec(root));
  if (root.Has("aabb")) {
    ICEF_ASSIGN_OR_RETURN(const auto b, root.NumberMatrix("aabb", 2, 3));
    Aabb aabb;
    aabb.min = Vec3f(float(b[0][0]), float(b[0][1]), float(b[0][2]));
    aabb.max = Vec3f(float(b[1][0]), float(b[1][1]), float(b[1][2]));
    if (!aabb.IsValid()) return root.Error("aabb", "min must be below max on every axis");
    h.aabb = aabb;
  }
  if (root.Has("expression_dim")) {
    ICEF_ASSIGN_OR_RETURN(const int dim, root.Int("expression_dim"));
    if (dim < 0) return root.Error("expression_dim", "must be >= 0");
    h.expression_dim = dim;
  }
  if (root.Has("expression_names")) {
    ICEF_ASSIGN_OR_RETURN(h.expression_names,
                          root.StringArray("expression_names", h.expression_dim.value_or(-1)));
  }
  if (root.Has("background")) {
    ICEF_ASSIGN_OR_RETURN(const std::vector<double> c, root.NumberArray("background", 3));
    for (double v : c)
      if (v < 0 || v > 1) return root.Error("background", "colour components must be in [0, 1]");
    h.background = Vec3f(float(c[0]), float(c[1]), float(c[2]));
  }
  if (root.Has("background_file_path")) {
    ICEF_ASSIGN_OR_RETURN(h.background_file_path, root.String("background_file_path"));
  }
  if (root.Has("tier_thresholds")) {
    ICEF_ASSIGN_OR_RETURN(const std::vector<double> t, root.NumberArray("tier_thresholds", 2));
    if (!(t[0] >= 0 && t[0] <= t[1])) return root.Error("tier_thresholds", "need 0 <= t0 <= t1");
    h.tier_thresholds = std::array<double, 2>{t[0], t[1]};
  }
  ICEF_ASSIGN_OR_RETURN(h.frames, root.ObjectArray("frames"));
  return h;
}

// Takes a file-level value into `merged`; a value given in several files must agree.
template <typename T, typename Eq>
Status Agree(const std::optional<T>& value, const SplitHeader& header, const char* key,
             std::optional<T>& merged, std::string& merged_from, Eq eq) {
  if (!value) return Status::Ok();
  if (merged && !eq(*merged, *value))
    return Status::Error(
        header.file + ": " + key + ": differs from the value in " + merged_from +
        " (aabb, expression_dim, expression_names, background and tier_thresholds must agree "
        "across splits)");
  if (!merged) {
    merged = value;
    merged_from = header.file;
  }
  return Status::Ok();
}

Result<Vec3f> MeanColour(const fs::path& path) {
  ICEF_ASSIGN_OR_RETURN(const Image image, ReadImage(path));
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int y = 0; y < image.height; ++y) {
    Eigen::Vector3d row = Eigen::Vector3d::Zero();
    for (int x = 0; x < image.width; ++x) row += image.Rgb(x, y).cast<double>();
    sum += row;
  }
  return Vec3f((sum / (double(image.width) * image.height)).cast<float>());
}

// NerFace keeps a background image in bg/ (its training uses bg/00050.png).
std::optional<std::string> FindNerfaceBackground(const fs::path& root) {
  std::error_code ec;
  if (fs::is_regular_file(root / "bg" / "00050.png", ec)) return "bg/00050.png";
  if (!fs::is_directory(root / "bg", ec)) return std::nullopt;
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(root / "bg", ec)) {
    const std::string ext = entry.path().extension().string();
    if (entry.is_regular_file() && (ext == ".png" || ext == ".jpg" || ext == ".jpeg"))
      names.push_back(entry.path().filename().string());
  }
  if (names.empty()) return std::nullopt;
  std::sort(names.begin(), names.end());
  return "bg/" + names.front();
}

// Parses the frames of one split, checks their images and builds their cameras.
Result<std::vector<Frame>> LoadFrames(const fs::path& root, const SplitHeader& header, int expression_dim,
                                      const Executor& executor) {
  const int n = static_cast<int>(header.frames.size());
  std::vector<ParsedFrame> parsed;
  parsed.reserve(n);
  for (int i = 0; i < n; ++i) {
    ICEF_ASSIGN_OR_RETURN(ParsedFrame p, ParseFrame(header.frames[i], expression_dim));
    parsed.push_back(std::move(p));
  }

  // Image existence, readability and size (file headers only), in parallel; each frame writes
  // its own slot, and the first failing frame by index is reported.
  std::vector<ImageCheck> checks(n);
  ParallelForChunks(executor, n, 8, [&](int64_t begin, int64_t end) {
    for (int64_t i = begin; i < end; ++i) {
      const JsonObjectView& f = header.frames[i];
      ImageCheck& c = checks[i];
      auto image = CheckImage(f, "file_path", root, parsed[i].frame.file_path);
      if (!image.ok()) {
        c.status = image.status();
        continue;
      }
      std::tie(c.file_path, c.info) = *image;
      if (const auto& neutral = parsed[i].frame.neutral_file_path) {
        auto neutral_image = CheckImage(f, "neutral_file_path", root, *neutral);
        if (!neutral_image.ok()) {
          c.status = neutral_image.status();
          continue;
        }
        if (neutral_image->second.width != c.info.width || neutral_image->second.height != c.info.height) {
          c.status = f.Error("neutral_file_path", "image size differs from the frame's image");
          continue;
        }
        c.neutral_file_path = neutral_image->first;
      }
    }
  });

  std::vector<Frame> frames;
  frames.reserve(n);
  for (int i = 0; i < n; ++i) {
    const JsonObjectView& f = header.frames[i];
    const ImageCheck& c = checks[i];
    ICEF_RETURN_IF_ERROR(c.status);
    ParsedFrame& p = parsed[i];
    const int w = p.camera.w.value_or(header.camera.w.value_or(c.info.width));
    const int h = p.camera.h.value_or(header.camera.h.value_or(c.info.height));
    if (c.info.width != w || c.info.height != h)
      return f.Error("file_path", "image " + (root / c.file_path).string() + " is " +
                                      std::to_string(c.info.width) + "x" + std::to_string(c.info.height) +
                                      ", but w x h is " + std::to_string(w) + "x" + std::to_string(h));
    const PartialIntrinsics local = Resolve(p.camera, w, h);
    const PartialIntrinsics global = Resolve(header.camera, w, h);
    Intrinsics k;
    k.width = w;
    k.height = h;
    if (!local.fl_x && !global.fl_x)
      return f.Error("fl_x",
                     "no focal length: give fl_x, camera_angle_x or intrinsics (in the file or the frame)");
    k.fl_x = local.fl_x ? *local.fl_x : *global.fl_x;
    k.fl_y = local.fl_y ? *local.fl_y : global.fl_y.value_or(k.fl_x);
    k.cx = local.cx ? *local.cx : global.cx.value_or(0.5 * w);
    k.cy = local.cy ? *local.cy : global.cy.value_or(0.5 * h);
    if (Status valid = k.Validate(); !valid.ok()) return f.ErrorHere("intrinsics: " + valid.message());
    p.frame.camera = Camera::Upright(k, p.world_from_cam);  // same rays; see the top of this file
    p.frame.file_path = c.file_path;
    if (c.neutral_file_path) p.frame.neutral_file_path = c.neutral_file_path;
    frames.push_back(std::move(p.frame));
  }
  return frames;
}

}  // namespace

Result<Dataset> LoadDataset(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    return Status::Error(dir.string() + ": not a dataset directory (does not exist or is not a directory)");
  const fs::path train_file = dir / "transforms_train.json";
  if (!fs::exists(train_file, ec))
    return Status::Error(train_file.string() +
                         ": not found (a dataset directory holds transforms_train.json)");

  // Parse every split file first: documents must outlive the views into them.
  const char* kSplits[] = {"train", "test", "val"};
  std::vector<Json> docs;
  std::vector<std::string> present;
  for (const char* split : kSplits) {
    const fs::path file = dir / ("transforms_" + std::string(split) + ".json");
    if (!fs::exists(file, ec)) continue;
    ICEF_ASSIGN_OR_RETURN(Json doc, ReadJsonFile(file));
    docs.push_back(std::move(doc));
    present.push_back(split);
  }
  std::vector<SplitHeader> headers;
  for (size_t s = 0; s < docs.size(); ++s) {
    const std::string file = (dir / ("transforms_" + present[s] + ".json")).string();
    ICEF_ASSIGN_OR_RETURN(const JsonObjectView root, JsonObjectView::Make(docs[s], file, ""));
    ICEF_ASSIGN_OR_RETURN(SplitHeader header, ParseHeader(root));
    headers.push_back(std::move(header));
  }

  // File-level values: given in one or more files, they must agree.
  std::optional<Aabb> aabb;
  std::optional<int> dim;
  std::optional<std::vector<std::string>> names;
  std::optional<Vec3f> background;
  std::optional<std::string> background_file;
  std::optional<std::array<double, 2>> thresholds;
  std::string from[6];
  auto same = [](const auto& a, const auto& b) { return a == b; };
  for (const SplitHeader& h : headers) {
    ICEF_RETURN_IF_ERROR(Agree(h.aabb, h, "aabb", aabb, from[0], [](const Aabb& a, const Aabb& b) {
      return a.min == b.min && a.max == b.max;
    }));
    ICEF_RETURN_IF_ERROR(Agree(h.expression_dim, h, "expression_dim", dim, from[1], same));
    ICEF_RETURN_IF_ERROR(Agree(h.expression_names, h, "expression_names", names, from[2], same));
    ICEF_RETURN_IF_ERROR(Agree(h.background, h, "background", background, from[3], same));
    ICEF_RETURN_IF_ERROR(
        Agree(h.background_file_path, h, "background_file_path", background_file, from[4], same));
    ICEF_RETURN_IF_ERROR(Agree(h.tier_thresholds, h, "tier_thresholds", thresholds, from[5], same));
  }

  // Expression dimension: declared, else the names' count, else the first training expression's length.
  const SplitHeader& train = headers.front();
  if (!dim && names) dim = static_cast<int>(names->size());
  if (!dim && !train.frames.empty() && train.frames[0].Has("expression")) {
    ICEF_ASSIGN_OR_RETURN(const std::vector<double> e, train.frames[0].NumberArray("expression"));
    dim = static_cast<int>(e.size());
  }
  if (names && dim && names->size() != size_t(*dim))
    return Status::Error(from[2] + ": expression_names: expected an array of " + std::to_string(*dim) +
                         " strings (expression_dim), got " + std::to_string(names->size()));

  Dataset dataset;
  dataset.root = dir;
  dataset.aabb = aabb.value_or(Aabb{});
  dataset.expression_dim = dim.value_or(0);
  dataset.expression_names = names.value_or(std::vector<std::string>{});
  dataset.tier_thresholds = thresholds;

  // Background: a colour, an image (NerFace), or both; the image's mean colour stands in for a
  // missing colour.
  if (!background && !background_file) background_file = FindNerfaceBackground(dir);
  if (background_file) {
    const fs::path path = dir / *background_file;
    if (!fs::is_regular_file(path, ec))
      return Status::Error((from[4].empty() ? dir.string() : from[4]) +
                           ": background_file_path: image not found: " + path.string());
    ICEF_ASSIGN_OR_RETURN(const ImageInfo info, ReadImageInfo(path));
    if (train.camera.w && train.camera.h && (info.width != *train.camera.w || info.height != *train.camera.h))
      return Status::Error(train.file + ": background_file_path: image is " + std::to_string(info.width) +
                           "x" + std::to_string(info.height) + ", but w x h is " +
                           std::to_string(*train.camera.w) + "x" + std::to_string(*train.camera.h));
    if (!background) {
      ICEF_ASSIGN_OR_RETURN(background, MeanColour(path));
    }
  }
  dataset.background = background.value_or(Vec3f::Ones());
  dataset.background_file_path = background_file;

  const Executor executor;
  for (size_t s = 0; s < headers.size(); ++s) {
    ICEF_ASSIGN_OR_RETURN(std::vector<Frame> frames,
                          LoadFrames(dir, headers[s], dataset.expression_dim, executor));
    if (present[s] == "train") dataset.train = std::move(frames);
    if (present[s] == "test") dataset.test = std::move(frames);
    if (present[s] == "val") dataset.val = std::move(frames);
  }
  return dataset;
}

}  // namespace icef
