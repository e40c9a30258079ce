#include "icef/train/face_depth.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <set>
#include <tuple>
#include <vector>

#include "icef/data/dataset.h"
#include "icef/face/face_model.h"
#include "icef/face/ict_model.h"
#include "icef/model/face_prior.h"
#include "icef/synth/identity.h"
#include "icef/synth/synthesize.h"
#include "icef/testing/tiny_dataset.h"

namespace icef {
namespace {

synth::SynthOptions SubjectOptions() {
  synth::SynthOptions o;
  o.out_dir = testing::MakeTempDir("face_depth_subject");
  o.identity_seed = 5;
  o.generic_style = true;
  o.num_train = 3;
  o.resolution = 96;
  o.test_views = 1;
  o.novel_per_tier = 1;
  o.head_scale = 0.8;
  o.head_offset = Vec3d(0.05, -0.03, 0.02);
  return o;
}

// The procedural fit's surface.
std::unique_ptr<FittedSurface> Surface(const face::FaceFit& fit,
                                       const std::vector<std::vector<float>>& expressions) {
  ModelSetup setup;
  setup.face_fit = fit;
  Result<std::unique_ptr<FittedSurface>> surface = FittedSurface::Create(setup, expressions);
  EXPECT_TRUE(surface.ok()) << surface.status().message();
  return std::move(surface).value();
}

// A style-free subject placed off the head frame (scaled and moved), so the fit's similarity is not
// the identity: each depth target's world point must land on the subject's own surface.
TEST(FaceDepthTest, TargetsLieOnTheSubjectsSurfaceInsideTheExpressionRegionsOnly) {
  const synth::SynthOptions o = SubjectOptions();
  const Executor ex(2);
  ASSERT_TRUE(synth::SynthesizeDataset(o, ex).ok());
  auto dataset = LoadDataset(o.out_dir);
  ASSERT_TRUE(dataset.ok()) << dataset.status().message();
  auto data = TrainingData::Load(*dataset);
  ASSERT_TRUE(data.ok()) << data.status().message();
  auto fit = FitFaceModelToDataset(*dataset);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  std::vector<std::vector<float>> expressions;
  for (const Frame& f : dataset->train) expressions.push_back(f.expression);

  const std::vector<float> depth =
      FaceModelDepthTargets(*Surface(*fit, expressions), *data, data->region_pixels(), ex);
  ASSERT_EQ(int64_t(depth.size()), data->num_pixels());
  const std::vector<float> one_thread =
      FaceModelDepthTargets(*Surface(*fit, expressions), *data, data->region_pixels(), Executor(1));
  EXPECT_EQ(std::memcmp(depth.data(), one_thread.data(), depth.size() * sizeof(float)), 0) << "thread count";

  const std::vector<int64_t>& region = data->region_pixels();
  ASSERT_FALSE(region.empty());
  std::vector<uint8_t> in_region(depth.size(), 0);
  for (int64_t p : region) in_region[p] = 1;
  for (size_t p = 0; p < depth.size(); ++p) {
    if (in_region[p]) continue;
    ASSERT_TRUE(std::isnan(depth[p])) << "pixel " << p << " outside the regions";
  }

  // The truth's surface, in the head frame: x_head = (x_world - offset) / scale.
  const synth::IdentityParams identity = synth::SynthIdentity(o);
  const face::FaceModel truth(identity.shape, identity.style);
  std::vector<double> distances;
  std::vector<Image> alphas;
  for (int k = 0; k < data->num_frames(); ++k) alphas.push_back(data->Alpha(k));
  int64_t covered = 0, hit = 0;
  for (int64_t p : region) {
    const int k = data->frame_of_pixel(p);
    const int64_t local = p - data->PixelIndex(k, 0, 0), width = data->camera(k).width();
    if (alphas[k].At(int(local % width), int(local / width), 0) < 1.f) continue;
    ++covered;
    if (!std::isfinite(depth[p])) continue;
    ++hit;
    const Ray ray = data->PixelCentreRay(p);
    const Vec3d x_world = ray.At(depth[p]).cast<double>();
    const Vec3f x_head = ((x_world - o.head_offset) / o.head_scale).cast<float>();
    distances.push_back(std::abs(truth.Distance(x_head, truth.Prepare(expressions[k]))));
  }
  ASSERT_GT(covered, 200);
  EXPECT_GT(hit, 0.97 * covered) << "the fitted head is missed inside the subject's silhouette";
  std::sort(distances.begin(), distances.end());
  const double median = distances[distances.size() / 2], p90 = distances[distances.size() * 9 / 10];
  // Measured: median 0.0002, 90th percentile 0.0003 head units (the fitted shape is not exact).
  EXPECT_LT(median, 0.001) << "head units";
  EXPECT_LT(p90, 0.002) << "head units";
}

// train.depth_prior_views: each unseen view is its training camera turned about one pivot by at most
// the options' angles (same intrinsics, same distance to the pivot, not the training view itself);
// its rays meet the subject's own surface at their depth, at their frame's expression, come from
// every frame, and do not depend on the thread count.
TEST(FaceDepthTest, UnseenViewRaysLieOnTheSubjectsSurface) {
  synth::SynthOptions o = SubjectOptions();
  o.out_dir = testing::MakeTempDir("face_depth_views");
  const Executor ex(2);
  ASSERT_TRUE(synth::SynthesizeDataset(o, ex).ok());
  auto dataset = LoadDataset(o.out_dir);
  ASSERT_TRUE(dataset.ok()) << dataset.status().message();
  auto data = TrainingData::Load(*dataset);
  ASSERT_TRUE(data.ok()) << data.status().message();
  auto fit = FitFaceModelToDataset(*dataset);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  std::vector<std::vector<float>> expressions;
  for (const Frame& f : dataset->train) expressions.push_back(f.expression);

  ViewRayOptions options;
  options.views_per_frame = 3;
  options.max_yaw_deg = 25;
  options.max_pitch_deg = 12;
  options.seed = 4;
  const auto cameras = UnseenViewCameras(*Surface(*fit, expressions), *data, options);
  ASSERT_EQ(int(cameras.size()), data->num_frames());
  // The pivot: the fitted face's centre (its neutral landmarks' mean), in the world.
  const face::FaceModel fitted(fit->shape, fit->style);
  Vec3d centre = Vec3d::Zero();
  for (const Vec3f& p : fitted.NeutralLandmarks()) centre += p.cast<double>() / 68.0;
  const Vec3d pivot = fit->head_from_world.ApplyInverse(centre);
  for (int k = 0; k < data->num_frames(); ++k) {
    ASSERT_EQ(cameras[k].size(), 3u);
    const Camera& train = data->camera(k);
    for (const Camera& view : cameras[k]) {
      EXPECT_EQ(view.intrinsics().fl_x, train.intrinsics().fl_x);
      const Mat3d turn =
          view.world_from_cam().block<3, 3>(0, 0) * train.world_from_cam().block<3, 3>(0, 0).transpose();
      const double angle = Eigen::AngleAxisd(turn).angle() * 180.0 / 3.14159265358979323846;
      EXPECT_LE(angle, std::hypot(25.0, 12.0) + 1e-6);
      EXPECT_GT(angle, 0.01);
      // The centre turns with the camera about the pivot.
      EXPECT_LT((view.Center() - pivot - turn * (train.Center() - pivot)).norm(), 1e-9);
    }
  }

  const std::vector<ViewRay> rays = FaceModelViewRays(*Surface(*fit, expressions), *data, options, ex);
  const std::vector<ViewRay> one_thread =
      FaceModelViewRays(*Surface(*fit, expressions), *data, options, Executor(1));
  ASSERT_EQ(rays.size(), one_thread.size());
  for (size_t i = 0; i < rays.size(); ++i) {
    ASSERT_EQ(rays[i].depth, one_thread[i].depth) << i;
    ASSERT_EQ(rays[i].ray.direction, one_thread[i].ray.direction) << i;
  }
  ASSERT_GT(rays.size(), 3u * 3u * 200u);  // about a tenth of each 96 x 96 view

  const synth::IdentityParams identity = synth::SynthIdentity(o);
  const face::FaceModel truth(identity.shape, identity.style);
  std::vector<double> distances;
  std::set<int> frames;
  for (const ViewRay& r : rays) {
    ASSERT_TRUE(std::isfinite(r.depth));
    frames.insert(r.frame);
    const Vec3d x_world = r.ray.At(r.depth).cast<double>();
    const Vec3f x_head = ((x_world - o.head_offset) / o.head_scale).cast<float>();
    distances.push_back(std::abs(truth.Distance(x_head, truth.Prepare(expressions[r.frame]))));
  }
  EXPECT_EQ(int(frames.size()), data->num_frames());
  std::sort(distances.begin(), distances.end());
  EXPECT_LT(distances[distances.size() / 2], 0.001) << "head units";
  EXPECT_LT(distances[distances.size() * 9 / 10], 0.002) << "head units";

  // train.depth_prior_view_region = "face": the expression region's rays and more (nose, cheeks,
  // chin), on the same surface.
  ViewRayOptions face_options = options;
  face_options.region = ViewRayOptions::Region::kFace;
  const std::vector<ViewRay> face_rays =
      FaceModelViewRays(*Surface(*fit, expressions), *data, face_options, ex);
  EXPECT_GT(face_rays.size(), rays.size() * 5 / 4);
  std::set<std::tuple<int, float, float, float>> face_set;
  for (const ViewRay& r : face_rays)
    face_set.insert({r.frame, r.ray.direction.x(), r.ray.direction.y(), r.ray.direction.z()});
  for (const ViewRay& r : rays)
    ASSERT_TRUE(face_set.count({r.frame, r.ray.direction.x(), r.ray.direction.y(), r.ray.direction.z()}));
  std::vector<double> face_distances;
  for (const ViewRay& r : face_rays) {
    const Vec3f x_head = ((r.ray.At(r.depth).cast<double>() - o.head_offset) / o.head_scale).cast<float>();
    face_distances.push_back(std::abs(truth.Distance(x_head, truth.Prepare(expressions[r.frame]))));
  }
  std::sort(face_distances.begin(), face_distances.end());
  EXPECT_LT(face_distances[face_distances.size() / 2], 0.001) << "head units";
  EXPECT_LT(face_distances[face_distances.size() * 9 / 10], 0.002) << "head units";

  // train.depth_prior_view_region = "upper": the expression region's rays above the mouth (brows and
  // eyes): a subset, every hit above the truth's upper lip at its frame's expression, where the
  // expression region's rays also reach below it.
  ViewRayOptions upper_options = options;
  upper_options.region = ViewRayOptions::Region::kUpper;
  const std::vector<ViewRay> upper_rays =
      FaceModelViewRays(*Surface(*fit, expressions), *data, upper_options, ex);
  EXPECT_GT(upper_rays.size(), rays.size() / 4);
  EXPECT_LT(upper_rays.size(), rays.size() * 3 / 4);
  std::set<std::tuple<int, float, float, float>> expression_set;
  for (const ViewRay& r : rays)
    expression_set.insert({r.frame, r.ray.direction.x(), r.ray.direction.y(), r.ray.direction.z()});
  const auto head_point = [&](const ViewRay& r) {
    return ((r.ray.At(r.depth).cast<double>() - o.head_offset) / o.head_scale).cast<float>().eval();
  };
  const auto lip_top = [&](int frame) {  // the truth's highest mouth landmark at that frame
    const std::array<Vec3f, 68> l = truth.Landmarks(truth.Prepare(expressions[frame]));
    float top = -1e9f;
    for (int i = 48; i < 68; ++i) top = std::max(top, l[i].y());
    return top;
  };
  for (const ViewRay& r : upper_rays) {
    ASSERT_TRUE(
        expression_set.count({r.frame, r.ray.direction.x(), r.ray.direction.y(), r.ray.direction.z()}));
    ASSERT_GT(head_point(r).y(), lip_top(r.frame));
  }
  int below_lip = 0;
  for (const ViewRay& r : rays) below_lip += head_point(r).y() < lip_top(r.frame);
  EXPECT_GT(below_lip, int(rays.size()) / 10);
  EXPECT_EQ(ViewRegionFromName("upper"), ViewRayOptions::Region::kUpper);
  EXPECT_EQ(ViewRegionFromName("face"), ViewRayOptions::Region::kFace);
  EXPECT_EQ(ViewRegionFromName("expression"), ViewRayOptions::Region::kExpression);

  options.views_per_frame = 0;
  EXPECT_TRUE(FaceModelViewRays(*Surface(*fit, expressions), *data, options, ex).empty());
}

// train.depth_prior_region = "eyes": each eye's landmark hull, dilated; inside the expression region,
// on every frame, holding every eye landmark's pixel and no mouth landmark's.
TEST(FaceDepthTest, EyePixelsAreTheEyesOfEveryFrame) {
  synth::SynthOptions o = SubjectOptions();
  o.out_dir = testing::MakeTempDir("face_depth_eyes");
  ASSERT_TRUE(synth::SynthesizeDataset(o, Executor(2)).ok());
  auto dataset = LoadDataset(o.out_dir);
  ASSERT_TRUE(dataset.ok()) << dataset.status().message();
  auto data = TrainingData::Load(*dataset);
  ASSERT_TRUE(data.ok()) << data.status().message();
  const std::vector<int64_t> eyes = EyePixels(*dataset, *data);
  std::vector<uint8_t> in_region(size_t(data->num_pixels()), 0), in_eyes(size_t(data->num_pixels()), 0);
  for (int64_t p : data->region_pixels()) in_region[p] = 1;
  for (int64_t p : eyes) in_eyes[p] = 1;
  ASSERT_LT(eyes.size(), data->region_pixels().size() / 2);
  for (int64_t p : eyes) EXPECT_TRUE(in_region[p]) << p;
  for (int k = 0; k < data->num_frames(); ++k) {
    const std::vector<Vec2f>& lm = *dataset->train[k].landmarks_2d;
    auto pixel = [&](int i) {
      return data->PixelIndex(k, int(std::floor(lm[i].x())), int(std::floor(lm[i].y())));
    };
    for (int i = 36; i < 48; ++i) EXPECT_TRUE(in_eyes[pixel(i)]) << "frame " << k << " landmark " << i;
    for (int i = 48; i < 68; ++i) EXPECT_FALSE(in_eyes[pixel(i)]) << "frame " << k << " landmark " << i;
    EXPECT_FALSE(in_eyes[pixel(30)]) << "frame " << k << ": the nose tip";
  }
}

// train.depth_prior_region = "face": the expression region and, on every frame, the hull of all 68
// landmarks (nose and cheeks too), and nothing outside the face.
TEST(FaceDepthTest, FacePixelsAreTheExpressionRegionAndTheLandmarkHull) {
  synth::SynthOptions o = SubjectOptions();
  o.out_dir = testing::MakeTempDir("face_depth_face");
  ASSERT_TRUE(synth::SynthesizeDataset(o, Executor(2)).ok());
  auto dataset = LoadDataset(o.out_dir);
  ASSERT_TRUE(dataset.ok()) << dataset.status().message();
  auto data = TrainingData::Load(*dataset);
  ASSERT_TRUE(data.ok()) << data.status().message();
  const std::vector<int64_t> face = FacePixels(*dataset, *data);
  ASSERT_TRUE(std::is_sorted(face.begin(), face.end()));
  ASSERT_TRUE(std::adjacent_find(face.begin(), face.end()) == face.end()) << "a pixel twice";
  std::vector<uint8_t> in_face(size_t(data->num_pixels()), 0);
  for (int64_t p : face) in_face[p] = 1;
  for (int64_t p : data->region_pixels()) EXPECT_TRUE(in_face[p]) << p;
  EXPECT_GT(face.size(), data->region_pixels().size() * 5 / 4) << "the cheeks and nose add pixels";
  EXPECT_LT(face.size(), size_t(data->num_pixels()) / 2) << "the face, not the image";
  for (int k = 0; k < data->num_frames(); ++k) {
    const std::vector<Vec2f>& lm = *dataset->train[k].landmarks_2d;
    auto pixel = [&](const Vec2f& p) {
      return data->PixelIndex(k, int(std::floor(p.x())), int(std::floor(p.y())));
    };
    EXPECT_TRUE(in_face[pixel(lm[30])]) << "frame " << k << ": the nose tip";
    EXPECT_TRUE(in_face[pixel(0.5f * (lm[2] + lm[30]))]) << "frame " << k << ": the right cheek";
    EXPECT_TRUE(in_face[pixel(0.5f * (lm[14] + lm[30]))]) << "frame " << k << ": the left cheek";
    EXPECT_FALSE(in_face[data->PixelIndex(k, 0, 0)]) << "frame " << k << ": the image corner";
  }
}

// ICT-FaceKit's surface (model/ict_prior.h's fit): the depth of the pixel under the nose tip is the
// distance to the posed mesh's nose tip; the landmarks are the posed mesh's, in the world frame.
TEST(FaceDepthTest, IctSurfaceIsThePosedMesh) {
  const face::IctModel& m = **face::IctModel::LoadDefault();
  ModelSetup setup;
  setup.ict_fit = IctFaceFit{};
  setup.ict_fit->head_from_world.scale = 40;  // 1 world unit = 40 cm
  setup.ict_fit->head_from_world.translation = Vec3d(0, 1, 0);
  std::vector<float> jaw(m.num_expressions(), 0.f);
  jaw[m.ExpressionIndex("jawOpen")] = 0.8f;
  const Result<std::unique_ptr<FittedSurface>> surface =
      FittedSurface::Create(setup, {std::vector<float>(m.num_expressions(), 0.f), jaw});
  ASSERT_TRUE(surface.ok()) << surface.status().message();
  const std::vector<Vec3f> mesh = m.Mesh({}, jaw);
  const std::array<Vec3f, 68> lm = (*surface)->Landmarks(1);
  const Vec3d nose = setup.ict_fit->head_from_world.ApplyInverse(m.Landmarks(mesh)[30].cast<double>());
  EXPECT_LT((lm[30].cast<double>() - nose).norm(), 1e-5);
  Intrinsics k;
  k.width = k.height = 64;
  k.fl_x = k.fl_y = 150;
  k.cx = k.cy = 32;
  const Camera camera = Camera::LookAt(k, nose + Vec3d(0, 0, 1.5), nose);
  const auto uv = camera.Project(nose);
  const int64_t pixel = int64_t(uv->uv.y()) * 64 + int64_t(uv->uv.x());
  const std::vector<float> d = (*surface)->Depths(camera, 1, std::vector<int64_t>{pixel, 0}, Executor(1));
  EXPECT_NEAR(d[0], 1.5, 0.01);   // within 0.4 cm: the pixel's ray passes within half a pixel of the tip
  EXPECT_TRUE(std::isnan(d[1]));  // the corner misses the head
  EXPECT_NEAR((*surface)->up.y(), 1.0, 1e-9);
  // No fit: an error.
  EXPECT_FALSE(FittedSurface::Create(ModelSetup{}, {}).ok());
}

}  // namespace
}  // namespace icef
