#include "icef/track/ict_track.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "icef/math/camera.h"

namespace icef::track {
namespace {

const face::IctModel& Model() {
  static const std::shared_ptr<const face::IctModel> model = [] {
    Result<std::shared_ptr<const face::IctModel>> m = face::IctModel::LoadDefault();
    EXPECT_TRUE(m.ok()) << m.status().message();
    return m.ok() ? *m : nullptr;
  }();
  return *model;
}

Intrinsics PhotoIntrinsics() {
  Intrinsics k;
  k.width = k.height = 400;
  k.fl_x = k.fl_y = 900;
  k.cx = k.cy = 200;
  return k;
}

// Head (cm) `distance` cm in front of the camera, turned by yaw degrees.
Mat4d CamFromIct(double yaw_deg, double distance = 60) {
  Mat4d m = Mat4d::Identity();
  m.block<3, 3>(0, 0) = Eigen::AngleAxisd(yaw_deg * M_PI / 180, Vec3d::UnitY()).toRotationMatrix();
  m.block<3, 1>(0, 3) = Vec3d(1, -2, -distance);
  return m;
}

struct Scene {
  std::vector<float> identity;
  std::vector<std::vector<float>> expressions;
  std::vector<Mat4d> cam_from_ict;
  std::vector<TrackFrame> frames;
};

// Three photos of one identity (jaw open in the second, a smile in the third): exact landmarks.
Scene MakeScene(const face::IctModel& m) {
  Scene s;
  s.identity = {0.8f, -0.5f, 0.3f, 0.6f, -0.4f};
  for (int k = 0; k < 3; ++k) {
    std::vector<float> beta(m.num_expressions(), 0.f);
    if (k == 1) beta[m.ExpressionIndex("jawOpen")] = 0.6f;
    if (k == 2)
      for (int e : m.ExpressionTargets("mouthSmile")) beta[e] = 0.5f;
    s.expressions.push_back(beta);
    s.cam_from_ict.push_back(CamFromIct(-25 + 25 * k));
    const Camera camera(PhotoIntrinsics(), s.cam_from_ict.back().inverse());
    TrackFrame f;
    f.intrinsics = camera.intrinsics();
    for (const Vec3f& p : m.Landmarks(m.Mesh(s.identity, beta)))
      f.landmarks_2d.push_back(camera.Project(p.cast<double>())->uv.cast<float>());
    s.frames.push_back(std::move(f));
  }
  return s;
}

TEST(IctTrack, FitIsInTheDatasetWorldFrame) {
  const face::IctModel& m = Model();
  const Scene s = MakeScene(m);
  const Result<TrackFit> fit = FitIctTrack(m, s.frames);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  ASSERT_EQ(fit->frames.size(), 3u);
  EXPECT_FALSE(fit->ict_identity.empty());
  EXPECT_LT(fit->rms_iod, 0.01);
  const face::Similarity world = WorldFromIctHead();
  for (int k = 0; k < 3; ++k) {
    const TrackedFrame& f = fit->frames[k];
    EXPECT_EQ(f.expression.size(), size_t(m.num_expressions()));
    ASSERT_TRUE(ValidateRigid(f.cam_from_head.inverse()).ok());
    // The world-frame landmarks, seen by the world-frame camera, land on the observed ones.
    const Camera camera(PhotoIntrinsics(), f.cam_from_head.inverse());
    for (int i = 17; i < 68; ++i) {
      const auto p = camera.Project(f.landmarks_head[i].cast<double>());
      ASSERT_TRUE(p.has_value());
      EXPECT_LT((p->uv.cast<float>() - s.frames[k].landmarks_2d[i]).norm(), 0.5f)
          << "photo " << k << " lm " << i;
    }
    // The camera sits where the truth's does, carried into the world frame (within 1 cm).
    const Vec3d truth_centre =
        world.Apply(-s.cam_from_ict[k].block<3, 3>(0, 0).transpose() * s.cam_from_ict[k].block<3, 1>(0, 3));
    EXPECT_LT((camera.Center() - truth_centre).norm(), kWorldPerCm * 1.0) << "photo " << k;
  }
  // The bounds hold every fitted landmark.
  const Aabb box = IctHeadBounds(m, fit->ict_identity, 0.05f);
  for (const TrackedFrame& f : fit->frames)
    for (const Vec3f& p : f.landmarks_head) EXPECT_TRUE(box.Contains(p));
  // About a head's size: 20-40 cm wide in world units.
  EXPECT_GT(box.Extent().x(), 20 * kWorldPerCm);
  EXPECT_LT(box.Extent().x(), 40 * kWorldPerCm);
}

TEST(IctTrack, SilhouetteCoversTheHeadAndNothingElse) {
  const face::IctModel& m = Model();
  const std::vector<float> neutral(m.num_expressions(), 0.f);
  const Mat4d cam_from_ict = CamFromIct(0, 130);  // the whole head and neck in view
  // The same camera in the world frame: centre carried by the similarity, rotation kept.
  const face::Similarity world = WorldFromIctHead();
  Mat4d world_from_cam = Mat4d::Identity();
  world_from_cam.block<3, 3>(0, 0) = cam_from_ict.block<3, 3>(0, 0).transpose();
  world_from_cam.block<3, 1>(0, 3) =
      world.Apply(-cam_from_ict.block<3, 3>(0, 0).transpose() * cam_from_ict.block<3, 1>(0, 3));
  const Camera camera(PhotoIntrinsics(), world_from_cam);
  const Image sil = IctSilhouette(m, {}, neutral, camera);
  ASSERT_EQ(sil.width, 400);
  // Every landmark of the face is covered; the image corners are not.
  const Camera ict_camera(PhotoIntrinsics(), cam_from_ict.inverse());
  for (const Vec3f& p : m.Landmarks(m.Mesh({}, neutral))) {
    const Vec2d uv = ict_camera.Project(p.cast<double>())->uv;
    EXPECT_EQ(sil.At(static_cast<int>(uv.x()), static_cast<int>(uv.y()), 0), 1.f);
  }
  for (const auto& [x, y] : {std::pair{0, 0}, {399, 0}, {0, 399}, {399, 399}})
    EXPECT_EQ(sil.At(x, y, 0), 0.f);
  // Its width is the head's: the neutral head's width at 130 cm (f = 900 px) within 10%.
  int widest = 0;
  for (int y = 0; y < 400; ++y) {
    int n = 0;
    for (int x = 0; x < 400; ++x) n += sil.At(x, y, 0) > 0;
    widest = std::max(widest, n);
  }
  const Aabb box = IctHeadBounds(m, {}, 0.f);
  const double expected = 900 * box.Extent().x() / kWorldPerCm / 130;
  EXPECT_NEAR(widest, expected, 0.1 * expected);
  // A camera looking away sees nothing.
  Mat4d away = world_from_cam;
  away.block<3, 3>(0, 0) =
      world_from_cam.block<3, 3>(0, 0) * Eigen::AngleAxisd(M_PI, Vec3d::UnitY()).toRotationMatrix();
  const Image none = IctSilhouette(m, {}, neutral, Camera(PhotoIntrinsics(), away));
  float sum = 0;
  for (const float v : none.pixels) sum += v;
  EXPECT_EQ(sum, 0.f);
}

}  // namespace
}  // namespace icef::track
