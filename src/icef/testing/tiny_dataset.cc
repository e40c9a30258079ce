#include "icef/testing/tiny_dataset.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "icef/core/rng.h"
#include "icef/io/atomic_file.h"
#include "icef/io/image.h"
#include "icef/io/json_util.h"

namespace icef::testing {

namespace fs = std::filesystem;

namespace {

// A smooth random image: a per-frame colour gradient, alpha a disc when requested.
Image RandomImage(int w, int h, int channels, Rng& rng) {
  Image image(w, h, channels);
  const Vec3f base(rng.Uniform(), rng.Uniform(), rng.Uniform());
  const Vec3f slope(rng.Uniform(), rng.Uniform(), rng.Uniform());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float t = (x + y) / float(w + h);
      for (int c = 0; c < 3; ++c) image.At(x, y, c) = std::fmod(base[c] + t * slope[c], 1.f);
      if (channels == 4) {
        const float dx = (x + 0.5f) / w - 0.5f, dy = (y + 0.5f) / h - 0.5f;
        image.At(x, y, 3) = (dx * dx + dy * dy < 0.16f) ? 1.f : 0.f;
      }
    }
  return image;
}

std::string Name(const char* split, int i) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "images/%s_%03d.png", split, i);
  return buffer;
}

Camera OrbitCamera(const Intrinsics& k, int index, int count) {
  const double yaw = count > 1 ? -0.4 + 0.8 * index / (count - 1) : 0.0;
  const Vec3d eye(3.0 * std::sin(yaw), 0.3, 3.0 * std::cos(yaw));
  return Camera::LookAt(k, eye, Vec3d::Zero());
}

std::vector<float> RandomExpression(int dim, Rng& rng) {
  std::vector<float> e(dim);
  for (float& v : e) v = static_cast<float>(rng.Uniform(-1.0, 1.0));
  return e;
}

double Distance(const std::vector<float>& a, const std::vector<float>& b) {
  double sum = 0;
  for (size_t i = 0; i < a.size(); ++i) sum += double(a[i] - b[i]) * double(a[i] - b[i]);
  return std::sqrt(sum);
}

}  // namespace

Status TinyDatasetOptions::Validate() const {
  if (num_train < 1 || num_test < 0 || num_val < 0)
    return Status::Error("need num_train >= 1, num_test/num_val >= 0");
  if (width < 1 || height < 1) return Status::Error("image size must be positive");
  if (expression_dim < 0) return Status::Error("expression_dim must be >= 0");
  return Status::Ok();
}

std::string TinyDatasetOptions::ToString() const {
  std::ostringstream os;
  os << "TinyDatasetOptions(train=" << num_train << ", test=" << num_test << ", val=" << num_val << ", "
     << width << "x" << height << ", B=" << expression_dim << ", landmarks_2d=" << landmarks_2d
     << ", landmarks_3d=" << landmarks_3d << ", alpha=" << alpha << ", seed=" << seed << ")";
  return os.str();
}

Dataset WriteTinyDataset(const fs::path& dir, const TinyDatasetOptions& options) {
  const Status valid = options.Validate();
  ICEF_CHECK(valid.ok(), valid.message());
  fs::create_directories(dir / "images");
  Dataset d;
  d.root = dir;
  d.aabb.min = Vec3f::Constant(-1.f);
  d.aabb.max = Vec3f::Constant(1.f);
  d.expression_dim = options.expression_dim;
  for (int i = 0; i < options.expression_dim; ++i)
    d.expression_names.push_back(std::string(1, 'e').append(std::to_string(i)));
  d.background = Vec3f(1.f, 1.f, 1.f);
  d.tier_thresholds = std::array<double, 2>{0.5, 1.0};

  Intrinsics k;
  k.width = options.width;
  k.height = options.height;
  k.fl_x = k.fl_y = 1.2 * options.width;
  k.cx = 0.5 * options.width;
  k.cy = 0.5 * options.height;

  std::vector<Vec3f> landmarks(kNumLandmarks);
  Rng landmark_rng(options.seed, StreamId("tiny_dataset/landmarks"));
  for (Vec3f& p : landmarks)
    p = Vec3f(landmark_rng.Uniform(-0.5, 0.5), landmark_rng.Uniform(-0.5, 0.5),
              landmark_rng.Uniform(-0.5, 0.5));

  const std::pair<const char*, int> splits[] = {
      {"train", options.num_train}, {"test", options.num_test}, {"val", options.num_val}};
  for (const auto& [split, count] : splits) {
    for (int i = 0; i < count; ++i) {
      Rng rng(options.seed, StreamId(split), 0, i);
      Frame f;
      f.file_path = Name(split, i);
      f.camera = OrbitCamera(k, i, count);
      f.expression = RandomExpression(options.expression_dim, rng);
      if (options.landmarks_3d) f.landmarks_3d = landmarks;
      if (options.landmarks_2d) {
        f.landmarks_2d.emplace();
        for (const Vec3f& p : landmarks) {
          const auto proj = f.camera.Project(p.cast<double>());
          ICEF_CHECK(proj.has_value(), "landmark behind the camera");
          f.landmarks_2d->push_back(proj->uv.cast<float>());
        }
      }
      if (std::string(split) == "test") {
        if (i == 0) f.expression = d.train[0].expression;
        double delta = 1e300;
        for (const Frame& t : d.train) delta = std::min(delta, Distance(f.expression, t.expression));
        f.delta = delta;
        f.tier = delta == 0     ? Tier::kObserved
                 : delta <= 0.5 ? Tier::kNear
                 : delta <= 1.0 ? Tier::kModerate
                                : Tier::kFar;
      }
      const Status written =
          WritePng(dir / f.file_path, RandomImage(options.width, options.height, options.alpha ? 4 : 3, rng));
      ICEF_CHECK(written.ok(), written.message());
      std::string s(split);
      (s == "train" ? d.train : s == "test" ? d.test : d.val).push_back(std::move(f));
    }
  }
  const Status saved = SaveDataset(d);
  ICEF_CHECK(saved.ok(), saved.message());
  return d;
}

Status TinyNerfaceOptions::Validate() const {
  if (num_train < 1 || num_val < 0 || num_test < 0) return Status::Error("need num_train >= 1");
  if (size < 1 || expression_dim < 1) return Status::Error("size and expression_dim must be positive");
  if (signed_focals && num_train < 3) return Status::Error("signed_focals needs num_train >= 3");
  return Status::Ok();
}

std::string TinyNerfaceOptions::ToString() const {
  std::ostringstream os;
  os << "TinyNerfaceOptions(train=" << num_train << ", val=" << num_val << ", test=" << num_test
     << ", size=" << size << ", B=" << expression_dim
     << ", signed_focals=" << (signed_focals ? "true" : "false") << ", seed=" << seed << ")";
  return os.str();
}

TinyNerfaceInfo WriteTinyNerfaceDataset(const fs::path& dir, const TinyNerfaceOptions& options) {
  const Status valid = options.Validate();
  ICEF_CHECK(valid.ok(), valid.message());
  TinyNerfaceInfo info;
  info.camera_angle_x = 0.5;
  const double focal = 0.5 * options.size / std::tan(0.5 * info.camera_angle_x);
  info.intrinsics = {focal * 1.01, focal * 0.99, 0.5, 0.45};
  const double fx = info.intrinsics[0], fy = info.intrinsics[1];
  if (options.signed_focals) {
    info.intrinsics[0] = -fx;
    info.intrinsics[1] = -fy;
  }

  fs::create_directories(dir / "bg");
  Rng bg_rng(options.seed, StreamId("tiny_nerface/background"));
  const Image background = RandomImage(options.size, options.size, 3, bg_rng);
  ICEF_CHECK(WritePng(dir / "bg" / "00050.png", background).ok());
  // The mean of the 8-bit values actually stored.
  const Image stored = ReadImage(dir / "bg" / "00050.png").value();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int y = 0; y < stored.height; ++y)
    for (int x = 0; x < stored.width; ++x) sum += stored.Rgb(x, y).cast<double>();
  info.background_mean = (sum / double(stored.width * stored.height)).cast<float>();

  Intrinsics k = Intrinsics::FromCameraAngle(options.size, options.size, info.camera_angle_x);
  const std::pair<const char*, int> splits[] = {
      {"train", options.num_train}, {"val", options.num_val}, {"test", options.num_test}};
  for (const auto& [split, count] : splits) {
    fs::create_directories(dir / split);
    Json doc = Json::object();
    doc["camera_angle_x"] = info.camera_angle_x;
    doc["intrinsics"] =
        Json::array({info.intrinsics[0], info.intrinsics[1], info.intrinsics[2], info.intrinsics[3]});
    Json frames = Json::array();
    for (int i = 0; i < count; ++i) {
      Rng rng(options.seed, StreamId(split), 0, i);
      char name[64];
      std::snprintf(name, sizeof name, "%s/f_%04d", split, i);
      ICEF_CHECK(
          WritePng(dir / (std::string(name) + ".png"), RandomImage(options.size, options.size, 3, rng)).ok());
      const Camera camera = OrbitCamera(k, i, count);
      Json m = Json::array();
      for (int r = 0; r < 4; ++r) {
        Json row = Json::array();
        for (int c = 0; c < 4; ++c) row.push_back(camera.world_from_cam()(r, c));
        m.push_back(row);
      }
      Json expression = Json::array();
      for (float v : RandomExpression(options.expression_dim, rng)) expression.push_back(JsonFloat(v));
      frames.push_back(Json{{"file_path", std::string("./") + name},
                            {"bbox", Json::array({0.1, 0.9, 0.2, 0.8})},
                            {"transform_matrix", m},
                            {"expression", expression}});
      if (options.signed_focals && std::string(split) == "train" && (i == 1 || i == 2)) {
        // Mirrored cameras: x flipped in frame 1, y flipped in frame 2.
        frames.back()["intrinsics"] = i == 1 ? Json::array({-1.2 * fx, 0.9 * fy, 0.48, 0.52})
                                             : Json::array({0.95 * fx, -1.1 * fy, 0.55, 0.5});
      }
    }
    doc["frames"] = frames;
    ICEF_CHECK(WriteFileAtomic(dir / ("transforms_" + std::string(split) + ".json"), FormatJson(doc)).ok());
  }
  return info;
}

RayD NerfaceRay(const Json& transforms, int index, int w, int h, int i, int j) {
  const Json& frame = transforms.at("frames").at(index);
  const Json& k = frame.contains("intrinsics") ? frame.at("intrinsics") : transforms.at("intrinsics");
  const double fx = k.at(0), fy = k.at(1), cx = k.at(2), cy = k.at(3);
  Mat4d c2w;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) c2w(r, c) = frame.at("transform_matrix").at(r).at(c).get<double>();
  const Vec3d dir_cam((i - w * cx) / fx, -(j - h * cy) / fy, -1.0);
  return RayD{c2w.block<3, 1>(0, 3), (c2w.block<3, 3>(0, 0) * dir_cam).normalized()};
}

fs::path MakeTempDir(const std::string& name) {
  static int counter = 0;
  const fs::path dir = fs::temp_directory_path() / "icef_test" /
                       (name + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

}  // namespace icef::testing
