#include "icef/track/track_fit.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "icef/core/rng.h"
#include "icef/face/expression.h"
#include "icef/face/face_model.h"
#include "icef/synth/ground_truth_renderer.h"
#include "icef/synth/head_model.h"
#include "icef/synth/identity.h"
#include "icef/track/head_mask.h"

namespace icef::track {
namespace {

face::ShapeParams KnownShape() {
  face::ShapeParams p;
  p.jaw_width = 1.08f;
  p.nose_length = 1.1f;
  p.eye_spacing = 0.95f;
  p.mouth_width = 1.06f;
  p.brow_height = 1.1f;
  return p;
}

Intrinsics PhotoIntrinsics() {
  Intrinsics k;
  k.width = 480;
  k.height = 640;
  k.fl_x = k.fl_y = 900;
  k.cx = 240;
  k.cy = 320;
  return k;
}

struct Truth {
  std::vector<TrackFrame> frames;
  std::vector<Mat4d> cam_from_head;
  std::vector<std::vector<float>> expression;
};

// Photos of the known head: each at its own pose (yaw within ±30°, pitch ±12°, roll ±8°) and
// expression, landmarks projected with Gaussian noise of `noise_px` pixels.
Truth MakePhotos(const face::FaceModel& head, int n, double noise_px, uint64_t seed) {
  Rng rng(seed, StreamId("track_fit_test"));
  // The face model's own landmarks, not dlib's.
  Truth t;
  for (int k = 0; k < n; ++k) {
    std::vector<float> beta(face::kNumExpressions, 0.f);
    if (k > 0)
      for (float& v : beta) v = rng.UniformDouble() < 0.35 ? static_cast<float>(rng.Uniform(0.1, 0.8)) : 0.f;
    const double yaw = rng.Uniform(-30, 30) * M_PI / 180, pitch = rng.Uniform(-12, 12) * M_PI / 180,
                 roll = rng.Uniform(-8, 8) * M_PI / 180;
    Mat4d cam_from_head = Mat4d::Identity();
    cam_from_head.block<3, 3>(0, 0) =
        (Eigen::AngleAxisd(roll, Vec3d::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3d::UnitX()) *
         Eigen::AngleAxisd(yaw, Vec3d::UnitY()))
            .toRotationMatrix();
    cam_from_head.block<3, 1>(0, 3) =
        Vec3d(rng.Uniform(-0.1, 0.1), rng.Uniform(-0.1, 0.1), -rng.Uniform(2.6, 3.4));
    const Camera camera(PhotoIntrinsics(), cam_from_head.inverse());
    TrackFrame f;
    f.intrinsics = PhotoIntrinsics();
    for (const Vec3f& p : head.Landmarks(head.Prepare(beta))) {
      const Vec2d uv = camera.Project(p.cast<double>())->uv + noise_px * Vec2d(rng.Normal(), rng.Normal());
      f.landmarks_2d.push_back(uv.cast<float>());
    }
    t.frames.push_back(f);
    t.cam_from_head.push_back(cam_from_head);
    t.expression.push_back(beta);
  }
  return t;
}

// Exact landmarks of the model's own convention with sub-pixel noise: weaker priors than dlib's
// noise calls for.
TrackFitOptions ModelConvention() {
  TrackFitOptions o;
  o.dlib_convention = false;
  o.landmark_sigma_iod = 0.02;
  o.shape_prior_sigma = 0.15;
  o.expression_prior_sigma = 0.6;
  return o;
}

double RotationErrorDeg(const Mat4d& a, const Mat4d& b) {
  const Mat3d r = a.block<3, 3>(0, 0).transpose() * b.block<3, 3>(0, 0);
  return Eigen::AngleAxisd(r).angle() * 180.0 / M_PI;
}

// RMS over the weights the 68 landmarks can see: cheek_puff moves none of them (the fit leaves it
// to its prior, 0), so it is left out here and reported separately by the tracker's evaluation.
double ExpressionRms(const std::vector<float>& a, const std::vector<float>& b) {
  double s = 0;
  int n = 0;
  for (size_t i = 0; i < a.size(); ++i)
    if (i != face::kCheekPuff) s += (a[i] - b[i]) * (a[i] - b[i]), ++n;
  return std::sqrt(s / n);
}

TEST(TrackFitTest, RecoversPosesAndExpressionsOfPhotos) {
  const face::FaceModel head(KnownShape());
  const Truth truth = MakePhotos(head, 5, 0.5, 7);
  const Result<TrackFit> result = FitTrack(truth.frames, ModelConvention());
  ASSERT_TRUE(result.ok()) << result.status().message();
  const TrackFit& fit = *result;
  ASSERT_EQ(fit.frames.size(), 5u);
  EXPECT_FALSE(fit.head_from_world.has_value());
  EXPECT_LT(fit.rms_iod, 0.03) << fit.BriefReport();
  const double head_height = 0.75;
  for (int k = 0; k < 5; ++k) {
    const TrackedFrame& f = fit.frames[k];
    EXPECT_LT(RotationErrorDeg(f.cam_from_head, truth.cam_from_head[k]), 2.0) << "photo " << k;
    const Vec3d dt = f.cam_from_head.block<3, 1>(0, 3) - truth.cam_from_head[k].block<3, 1>(0, 3);
    EXPECT_LT(dt.norm() / head_height, 0.1) << "photo " << k;  // depth is the weak direction
    EXPECT_LT(ExpressionRms(f.expression, truth.expression[k]), 0.1) << "photo " << k;

    for (float v : f.expression) EXPECT_GE(v, 0.f);
  }
}

// The Laplace prior leaves the weights a photo does not show at exactly 0 where the Gaussian prior
// alone lets the landmarks' noise spread small values over them, and still finds those it shows.
TEST(TrackFitTest, LaplacePriorLeavesUnshownExpressionsAtZero) {
  const face::FaceModel head(KnownShape());
  const Truth truth = MakePhotos(head, 5, 1.5, 11);
  TrackFitOptions o = ModelConvention();
  const Result<TrackFit> gaussian = FitTrack(truth.frames, o);
  o.expression_prior_laplace = 0.3;
  const Result<TrackFit> laplace = FitTrack(truth.frames, o);
  ASSERT_TRUE(gaussian.ok() && laplace.ok());
  int unshown = 0, zero_gaussian = 0, zero_laplace = 0;
  double rms_gaussian = 0, rms_laplace = 0;
  for (int k = 0; k < 5; ++k) {
    for (int e = 0; e < face::kNumExpressions; ++e) {
      if (e == face::kCheekPuff || truth.expression[k][e] > 0) continue;
      ++unshown;
      zero_gaussian += gaussian->frames[k].expression[e] < 1e-4f;
      zero_laplace += laplace->frames[k].expression[e] < 1e-4f;
    }
    rms_gaussian += std::pow(ExpressionRms(gaussian->frames[k].expression, truth.expression[k]), 2) / 5;
    rms_laplace += std::pow(ExpressionRms(laplace->frames[k].expression, truth.expression[k]), 2) / 5;
  }
  std::printf("unshown weights at 0: %d of %d (Gaussian), %d (Laplace); expression RMS %.3f, %.3f\n",
              zero_gaussian, unshown, zero_laplace, std::sqrt(rms_gaussian), std::sqrt(rms_laplace));
  EXPECT_GE(zero_laplace, zero_gaussian + unshown / 4);
  EXPECT_LT(std::sqrt(rms_laplace), std::sqrt(rms_gaussian));
}

// The head's exact silhouette in each photo (traced at a quarter of the resolution), as edge points.
void AddSilhouettes(const face::FaceModel& head, Truth* truth, int max_points) {
  for (size_t k = 0; k < truth->frames.size(); ++k) {
    Intrinsics small = PhotoIntrinsics();
    small.width /= 4, small.height /= 4, small.fl_x /= 4, small.fl_y /= 4, small.cx /= 4, small.cy /= 4;
    const Image mask =
        HeadSilhouette(head, truth->expression[k], Camera(small, truth->cam_from_head[k].inverse()));
    truth->frames[k].silhouette = MaskEdgePoints(mask, Image(), max_points);
    for (Vec2f& p : truth->frames[k].silhouette) p *= 4.f;
  }
}

double MedianRotationErrorDeg(const TrackFit& fit, const Truth& truth) {
  std::vector<double> e;
  for (size_t k = 0; k < fit.frames.size(); ++k)
    e.push_back(RotationErrorDeg(fit.frames[k].cam_from_head, truth.cam_from_head[k]));
  std::sort(e.begin(), e.end());
  return e[e.size() / 2];
}

// Landmarks as noisy as dlib's on our head (about 0.06 IOD): the silhouettes pin the pose, and
// edge points the head does not explain (hair beside the cheeks) are left out.
TEST(TrackFitTest, SilhouettesSharpenThePose) {
  const face::FaceModel head(KnownShape());
  Truth truth = MakePhotos(head, 4, 4.0, 21);
  TrackFitOptions o = ModelConvention();
  o.landmark_sigma_iod = 0.06;
  o.silhouette_face_only = false;  // the head has no hair: its whole outline
  const Result<TrackFit> landmarks_only = FitTrack(truth.frames, o);
  ASSERT_TRUE(landmarks_only.ok()) << landmarks_only.status().message();
  EXPECT_EQ(landmarks_only->frames[0].silhouette_used, 0);
  AddSilhouettes(head, &truth, 200);
  std::vector<size_t> head_points;
  for (TrackFrame& f : truth.frames) {
    head_points.push_back(f.silhouette.size());
    // "Hair": copies of the points level with the nose, pushed 0.6 IOD sideways out of the face.
    const float iod_px = (f.landmarks_2d[45] - f.landmarks_2d[36]).norm();
    const Vec2f nose = f.landmarks_2d[30];
    for (size_t i = 0, n = f.silhouette.size(); i < n; ++i) {
      const Vec2f p = f.silhouette[i];
      if (std::abs(p.y() - nose.y()) < 0.3f * iod_px)
        f.silhouette.push_back(p + Vec2f(p.x() < nose.x() ? -0.6f * iod_px : 0.6f * iod_px, 0.f));
    }
    ASSERT_GT(f.silhouette.size(), head_points.back());
  }
  const Result<TrackFit> with = FitTrack(truth.frames, o);
  ASSERT_TRUE(with.ok()) << with.status().message();
  for (size_t k = 0; k < with->frames.size(); ++k) {
    const TrackedFrame& f = with->frames[k];
    EXPECT_GT(f.silhouette_used, 0.6 * head_points[k]) << "frame " << k;
    EXPECT_LE(f.silhouette_used, static_cast<int>(head_points[k])) << "frame " << k;  // no hair
    EXPECT_LT(f.silhouette_rms_iod, 0.03) << f.ToString();
  }
  const double before = MedianRotationErrorDeg(*landmarks_only, truth),
               after = MedianRotationErrorDeg(*with, truth);
  std::printf("median rotation error: %.2f deg from landmarks, %.2f deg with silhouettes\n", before, after);
  EXPECT_LT(after, 1.5);
  EXPECT_LT(after, 0.6 * before);
  // The face region alone (the default): only the points between the chin and the brows.
  o.silhouette_face_only = true;
  const Result<TrackFit> face = FitTrack(truth.frames, o);
  ASSERT_TRUE(face.ok()) << face.status().message();
  for (size_t k = 0; k < face->frames.size(); ++k) {
    EXPECT_GT(face->frames[k].silhouette_used, 0.15 * head_points[k]) << "frame " << k;
    EXPECT_LT(face->frames[k].silhouette_used, 0.6 * head_points[k]) << "frame " << k;
  }
}

// A silhouette refit that drives a shape scale onto its bound has degenerated: the landmarks' fit
// stays, and the fit says why. Here the outlines are a wider skull's than the landmarks' head, and
// head_width may not pass 1.06.
TEST(TrackFitTest, ASilhouetteRefitOnAShapeBoundKeepsTheLandmarkFit) {
  const face::FaceModel head(KnownShape());
  Truth truth = MakePhotos(head, 4, 0.3, 31);
  TrackFitOptions o = ModelConvention();
  o.silhouette_face_only = false;
  o.shape_max = 1.06;
  const Result<TrackFit> landmarks_only = FitTrack(truth.frames, o);
  ASSERT_TRUE(landmarks_only.ok()) << landmarks_only.status().message();
  EXPECT_EQ(landmarks_only->silhouettes, "off");
  ASSERT_LT(landmarks_only->shape.head_width, 1.05f);
  face::ShapeParams wide = KnownShape();
  wide.head_width = 1.2f;
  AddSilhouettes(face::FaceModel(wide), &truth, 200);
  const Result<TrackFit> refit = FitTrack(truth.frames, o);
  ASSERT_TRUE(refit.ok()) << refit.status().message();
  EXPECT_EQ(refit->silhouettes.rfind("not used: the head's head_width ran to its bound", 0), 0u)
      << refit->silhouettes;
  EXPECT_NE(refit->BriefReport().find("silhouette refit not used"), std::string::npos);
  EXPECT_FLOAT_EQ(refit->shape.head_width, landmarks_only->shape.head_width);
  for (size_t k = 0; k < refit->frames.size(); ++k) {
    EXPECT_TRUE(refit->frames[k].cam_from_head.isApprox(landmarks_only->frames[k].cam_from_head, 1e-9)) << k;
    EXPECT_EQ(refit->frames[k].silhouette_used, 0) << k;
  }
  // Within the usual bounds the same outlines are used.
  o.shape_max = TrackFitOptions().shape_max;
  const Result<TrackFit> free = FitTrack(truth.frames, o);
  ASSERT_TRUE(free.ok()) << free.status().message();
  EXPECT_EQ(free->silhouettes, "used");
  EXPECT_GT(free->shape.head_width, 1.06f);
  TrackFitOptions bad;
  bad.shape_min = 1.2;
  EXPECT_FALSE(bad.Validate().ok());
}

TEST(TrackFitTest, KnownCamerasGiveTheSharedSimilarity) {
  const face::FaceModel head(KnownShape());
  Truth truth = MakePhotos(head, 4, 0.3, 11);
  // The same views as known cameras in a world frame = head frame scaled by 0.5 and shifted.
  face::Similarity true_sim;
  true_sim.scale = 2.0;
  true_sim.translation = Vec3d(0.1, -0.05, 0.0);
  Mat4d world_from_head = Mat4d::Identity();
  world_from_head.block<3, 3>(0, 0) *= 1.0 / true_sim.scale;
  world_from_head.block<3, 1>(0, 3) = -true_sim.translation / true_sim.scale;
  for (int k = 0; k < 4; ++k) {
    // world_from_cam = world_from_head * head_from_cam, made rigid by moving the centre only.
    Mat4d head_from_cam = truth.cam_from_head[k].inverse();
    Mat4d w = Mat4d::Identity();
    w.block<3, 3>(0, 0) = head_from_cam.block<3, 3>(0, 0);
    w.block<3, 1>(0, 3) = (world_from_head * head_from_cam.col(3)).head<3>();
    // The image of the world-scaled head is the same as the head seen from the scaled centre.
    truth.frames[k].world_from_cam = w;
  }
  const Result<TrackFit> result = FitTrack(truth.frames, ModelConvention());
  ASSERT_TRUE(result.ok()) << result.status().message();
  const TrackFit& fit = *result;
  ASSERT_TRUE(fit.head_from_world.has_value());
  EXPECT_NEAR(fit.head_from_world->scale, 2.0, 0.1);
  EXPECT_LT((fit.head_from_world->translation - true_sim.translation).norm(), 0.05);
  for (int k = 0; k < 4; ++k) EXPECT_LT(ExpressionRms(fit.frames[k].expression, truth.expression[k]), 0.1);
}

// A detector that sees a third of each expression (as dlib's mouth points on our heads): the
// landmarks alone read the expressions a third as strong; the photos show them whole, and the
// photometric refit reads them from there.
TEST(TrackFitTest, PhotometricRefitReadsWhatTheLandmarksMiss) {
  synth::IdentityParams identity = synth::IdentityParams::FromSeed(5);
  identity.shape = KnownShape();
  identity.style = face::ExpressionStyle::Generic();
  const synth::HeadModel head(identity);
  const face::FaceModel& face = head.face();
  Intrinsics k;  // small photos: the test renders them
  k.width = 240, k.height = 320, k.fl_x = k.fl_y = 450, k.cx = 120, k.cy = 160;
  std::vector<std::vector<float>> expressions(4, std::vector<float>(face::kNumExpressions, 0.f));
  expressions[1][face::kJawOpen] = 0.7f;
  expressions[2][face::kSmileLeft] = 0.6f;
  expressions[2][face::kBrowRaiseRight] = 0.5f;
  expressions[3][face::kJawOpen] = 0.4f;
  expressions[3][face::kSmileRight] = 0.5f;
  const double yaws[4] = {-12, 8, 15, -4};
  std::vector<Image> photos;
  std::vector<TrackFrame> frames;
  std::vector<Mat4d> true_pose;
  for (int i = 0; i < 4; ++i) {
    Mat4d cam_from_head = Mat4d::Identity();
    cam_from_head.block<3, 3>(0, 0) =
        Eigen::AngleAxisd(yaws[i] * M_PI / 180, Vec3d::UnitY()).toRotationMatrix();
    cam_from_head.block<3, 1>(0, 3) = Vec3d(0.02 * i, -0.03, -2.8);
    const Camera camera(k, cam_from_head.inverse());
    Image rgba = synth::RenderGroundTruth(head, camera, expressions[i]);
    Image rgb(k.width, k.height, 3);
    for (int y = 0; y < k.height; ++y)  // over a grey gradient
      for (int x = 0; x < k.width; ++x)
        for (int c = 0; c < 3; ++c)
          rgb.At(x, y, c) =
              rgba.At(x, y, 3) * rgba.At(x, y, c) + (1 - rgba.At(x, y, 3)) * (0.3f + 0.4f * x / k.width);
    photos.push_back(std::move(rgb));
    std::vector<float> seen = expressions[i];
    for (float& v : seen) v /= 3.f;
    TrackFrame f;
    f.intrinsics = k;
    for (const Vec3f& p : face.Landmarks(face.Prepare(seen)))
      f.landmarks_2d.push_back(camera.Project(p.cast<double>())->uv.cast<float>());
    frames.push_back(f);
    true_pose.push_back(cam_from_head);
  }
  TrackFitOptions o = ModelConvention();
  o.landmark_sigma_iod = 0.05;
  o.expression_prior_sigma = 0.3;
  o.shape_prior_sigma = 0.05;
  // The refit alone: the Laplace prior (LaplacePriorLeavesUnshownExpressionsAtZero) pulls every
  // weight towards 0, and these landmarks already show a third of each expression.
  o.photometric_expression_prior_laplace = 0;
  const Result<TrackFit> landmarks_only = FitTrack(frames, o);  // no photos: no refit
  ASSERT_TRUE(landmarks_only.ok()) << landmarks_only.status().message();
  EXPECT_EQ(landmarks_only->frames[1].photometric_used, 0);
  for (int i = 0; i < 4; ++i) frames[i].photo = &photos[i];
  const Result<TrackFit> with = FitTrack(frames, o);
  ASSERT_TRUE(with.ok()) << with.status().message();
  double before = 0, after = 0;
  for (int i = 0; i < 4; ++i) {
    before += std::pow(ExpressionRms(landmarks_only->frames[i].expression, expressions[i]), 2) / 4;
    after += std::pow(ExpressionRms(with->frames[i].expression, expressions[i]), 2) / 4;
    EXPECT_GT(with->frames[i].photometric_used, 100) << with->frames[i].ToString();
    EXPECT_LT(with->frames[i].photometric_rms, 0.05) << with->frames[i].ToString();
    // Loose: the landmarks misstate the expressions, and the pose takes up some of it.
    EXPECT_LT(RotationErrorDeg(with->frames[i].cam_from_head, true_pose[i]), 3.0) << "photo " << i;
  }
  before = std::sqrt(before), after = std::sqrt(after);
  std::printf("expression RMS: %.3f from the landmarks, %.3f with the photos\n", before, after);
  for (int i = 0; i < 4; ++i) {
    std::printf("photo %d (true / landmarks / photos):", i);
    for (int e = 0; e < face::kNumExpressions; ++e)
      if (expressions[i][e] > 0 || with->frames[i].expression[e] > 0.05 ||
          landmarks_only->frames[i].expression[e] > 0.05)
        std::printf(" %s %.2f/%.2f/%.2f", face::kExpressionNames[e], expressions[i][e],
                    landmarks_only->frames[i].expression[e], with->frames[i].expression[e]);
    std::printf("\n");
  }
  EXPECT_LT(after, 0.85 * before);
  // The expressions the photos show most: the jaw's error at least halved, the smiles' cut by a quarter.
  const auto error = [&](const Result<TrackFit>& fit, int i, int e) {
    return std::abs(fit->frames[i].expression[e] - expressions[i][e]);
  };
  for (int i : {1, 3})
    EXPECT_LT(error(with, i, face::kJawOpen), 0.5 * error(landmarks_only, i, face::kJawOpen))
        << "photo " << i;
  EXPECT_LT(error(with, 2, face::kSmileLeft), 0.75 * error(landmarks_only, 2, face::kSmileLeft));
  EXPECT_LT(error(with, 3, face::kSmileRight), 0.75 * error(landmarks_only, 3, face::kSmileRight));
  for (float v : with->frames[0].expression) EXPECT_LT(v, 0.1f);  // the neutral photo stays neutral
  EXPECT_EQ(with->photometric, "used");
  EXPECT_EQ(landmarks_only->photometric, "off");

  // Another exposure and white balance in one photo: its gain absorbs it.
  std::vector<Image> exposed = photos;
  for (size_t i = 0; i < exposed[3].pixels.size(); ++i) exposed[3].pixels[i] *= i % 3 == 2 ? 0.6f : 0.75f;
  for (int i = 0; i < 4; ++i) frames[i].photo = &exposed[i];
  const Result<TrackFit> darker = FitTrack(frames, o);
  ASSERT_TRUE(darker.ok()) << darker.status().message();
  EXPECT_EQ(darker->photometric, "used");
  for (int i = 0; i < 4; ++i)
    EXPECT_LT(ExpressionRms(darker->frames[i].expression, with->frames[i].expression), 0.03) << "photo " << i;

  // A band drawn across the face of two photos: the colours disagree, and the landmark fit stands.
  std::vector<Image> drawn = photos;
  for (int i : {1, 2}) {
    const Vec2f nose = frames[i].landmarks_2d[33], chin = frames[i].landmarks_2d[8];
    for (int y = static_cast<int>(nose.y()); y < static_cast<int>(chin.y()); ++y)
      for (int x = 0; x < k.width; ++x)
        drawn[i].At(x, y, 0) = 1.f, drawn[i].At(x, y, 1) = 0.f, drawn[i].At(x, y, 2) = 1.f;
  }
  for (int i = 0; i < 4; ++i) frames[i].photo = &drawn[i];
  const Result<TrackFit> rejected = FitTrack(frames, o);
  ASSERT_TRUE(rejected.ok()) << rejected.status().message();
  EXPECT_EQ(rejected->photometric.rfind("not used: the images' colours disagree", 0), 0u)
      << rejected->photometric;
  EXPECT_GT(rejected->frames[2].photometric_rms, o.photometric_max_rms);
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(rejected->frames[i].expression, landmarks_only->frames[i].expression) << "photo " << i;
}

TEST(TrackFitTest, YawPitchRollFollowTheirConvention) {
  TrackedFrame f;
  const double yaw = 0.3, pitch = -0.2, roll = 0.1;
  f.cam_from_head.block<3, 3>(0, 0) =
      (Eigen::AngleAxisd(roll, Vec3d::UnitZ()) * Eigen::AngleAxisd(-pitch, Vec3d::UnitX()) *
       Eigen::AngleAxisd(yaw, Vec3d::UnitY()))
          .toRotationMatrix();
  const Vec3d ypr = f.YawPitchRollDeg();
  EXPECT_NEAR(ypr.x(), yaw * 180 / M_PI, 1e-9);
  EXPECT_NEAR(ypr.y(), pitch * 180 / M_PI, 1e-9);
  EXPECT_NEAR(ypr.z(), roll * 180 / M_PI, 1e-9);
  // Positive pitch lifts the chin: the face's +z turns toward the camera's +y.
  f.cam_from_head.block<3, 3>(0, 0) = Eigen::AngleAxisd(-0.2, Vec3d::UnitX()).toRotationMatrix();
  EXPECT_GT((f.cam_from_head.block<3, 3>(0, 0) * Vec3d::UnitZ()).y(), 0);
  EXPECT_GT(f.YawPitchRollDeg().y(), 0);
}

TEST(TrackFitTest, BadInputIsAnError) {
  EXPECT_FALSE(FitTrack({}).ok());
  const face::FaceModel head(KnownShape());
  Truth truth = MakePhotos(head, 2, 0, 3);
  truth.frames[1].landmarks_2d.pop_back();
  EXPECT_NE(
      FitTrack(truth.frames, ModelConvention()).status().message().find("frame 1: landmarks_2d must have 68"),
      std::string::npos);
  truth = MakePhotos(head, 2, 0, 3);
  truth.frames[0].world_from_cam = Mat4d::Identity();
  EXPECT_NE(
      FitTrack(truth.frames, ModelConvention()).status().message().find("known for every frame or for none"),
      std::string::npos);
  truth = MakePhotos(head, 2, 0, 3);
  truth.frames[1].landmarks_2d[5].x() = NAN;
  EXPECT_FALSE(FitTrack(truth.frames, ModelConvention()).ok());
  TrackFitOptions bad;
  bad.max_expression = 0;
  EXPECT_FALSE(FitTrack(MakePhotos(head, 2, 0, 3).frames, bad).ok());
}

}  // namespace
}  // namespace icef::track
