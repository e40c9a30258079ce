#include "icef/face/ict_fit.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>

#include "icef/core/rng.h"

namespace icef::face {
namespace {

// The model at DefaultPath(), loaded once; nullptr when the file is absent (tests skip).
const face::IctModel* Model() {
  static const Result<face::IctModel>* loaded = [] {
    const std::filesystem::path path = face::IctModel::DefaultPath();
    return std::filesystem::exists(path) ? new Result<face::IctModel>(face::IctModel::Load(path)) : nullptr;
  }();
  if (loaded == nullptr) return nullptr;
  EXPECT_TRUE(loaded->ok()) << loaded->status().message();
  return loaded->ok() ? &loaded->value() : nullptr;
}

#define ICT_MODEL_OR_SKIP(m)                                                                    \
  const face::IctModel* m##_ptr = Model();                                                      \
  if (m##_ptr == nullptr) GTEST_SKIP() << "no face model at " << face::IctModel::DefaultPath(); \
  const face::IctModel& m = *m##_ptr

constexpr int kTruthIdentity = 40;

Intrinsics PhotoIntrinsics() {
  Intrinsics k;
  k.width = k.height = 512;
  k.fl_x = k.fl_y = 1000;
  k.cx = k.cy = 256;
  return k;
}

// What the synthetic photos show.
struct Truth {
  std::vector<float> identity;                 // [40]
  std::vector<Mat4d> cam_from_head;            // per photo
  std::vector<std::vector<float>> expression;  // per photo [53]
};

// cam_from_head = Rz(roll) Rx(-pitch) Ry(yaw) (track_fit.h's angles), the head's origin ~60 cm
// in front of the camera.
Mat4d Pose(double yaw_deg, double pitch_deg, double roll_deg, const Vec3d& translation) {
  const double d = M_PI / 180;
  Mat4d m = Mat4d::Identity();
  m.block<3, 3>(0, 0) =
      (Eigen::AngleAxisd(roll_deg * d, Vec3d::UnitZ()) * Eigen::AngleAxisd(-pitch_deg * d, Vec3d::UnitX()) *
       Eigen::AngleAxisd(yaw_deg * d, Vec3d::UnitY()))
          .toRotationMatrix();
  m.block<3, 1>(0, 3) = translation;
  return m;
}

// Sparse expressions: each group is on with probability 1/2 at a weight in [0, 0.8]; the halves
// of a pair differ by at most 0.1.
std::vector<float> RandomExpression(const face::IctModel& m, Rng& rng) {
  std::vector<float> w(m.num_expressions(), 0.f);
  for (const char* group : {"jawOpen", "mouthSmile", "eyeBlink", "browInnerUp", "mouthFunnel", "browDown"}) {
    if (rng.UniformDouble() < 0.5) continue;
    const double v = rng.Uniform(0.0, 0.8);
    const int single = m.ExpressionIndex(group);
    if (single >= 0) {
      w[single] = static_cast<float>(v);
      continue;
    }
    for (const char* side : {"_L", "_R"})
      w[m.ExpressionIndex(std::string(group) + side)] =
          static_cast<float>(std::clamp(v + rng.Uniform(-0.05, 0.05), 0.0, 1.0));
  }
  return w;
}

Truth MakeTruth(const face::IctModel& m, int photos, uint64_t seed) {
  Rng rng(seed, StreamId("ict_track_fit_test truth"));
  Truth t;
  for (int i = 0; i < kTruthIdentity; ++i) t.identity.push_back(static_cast<float>(0.7 * rng.Normal()));
  for (int k = 0; k < photos; ++k) {
    // Yaw spread over [-35, 35] degrees so that the views differ; pitch and roll at random.
    const double yaw = -35 + 70.0 * k / std::max(photos - 1, 1) + rng.Uniform(-5, 5);
    const Vec3d offset(rng.Uniform(-3, 3), rng.Uniform(-3, 3), -60 + rng.Uniform(-5, 5));
    t.cam_from_head.push_back(
        Pose(std::clamp(yaw, -35.0, 35.0), rng.Uniform(-15, 15), rng.Uniform(-5, 5), offset));
    // Photo 0 neutral, the others at random.
    t.expression.push_back(k == 0 ? std::vector<float>(m.num_expressions(), 0.f) : RandomExpression(m, rng));
  }
  return t;
}

// The true landmarks projected by math/camera.h's Camera, plus Gaussian noise (pixels).
std::vector<IctObservation> Observe(const face::IctModel& m, const Truth& t, double noise_px, uint64_t seed) {
  Rng rng(seed, StreamId("ict_track_fit_test noise"));
  std::vector<IctObservation> out;
  for (size_t k = 0; k < t.cam_from_head.size(); ++k) {
    const Camera camera(PhotoIntrinsics(), t.cam_from_head[k].inverse());
    const std::vector<Vec3f> lm = m.Landmarks(m.Mesh(t.identity, t.expression[k]));
    IctObservation o;
    o.intrinsics = camera.intrinsics();
    for (const Vec3f& p : lm) {
      const auto uv = camera.Project(p.cast<double>());
      EXPECT_TRUE(uv.has_value());
      const Vec2d noise(rng.Normal(), rng.Normal());
      o.landmarks.push_back((uv->uv + noise_px * noise).cast<float>());
    }
    out.push_back(std::move(o));
  }
  return out;
}

double RotationErrorDeg(const Mat4d& a, const Mat4d& b) {
  const Mat3d d = a.block<3, 3>(0, 0).transpose() * b.block<3, 3>(0, 0);
  return Eigen::AngleAxisd(d).angle() * 180 / M_PI;
}

// The largest weight error over the named expressions (both halves of a pair) and all photos.
double ExpressionError(const face::IctModel& m, const Truth& t, const IctFit& fit, const std::string& name) {
  double worst = 0;
  for (size_t k = 0; k < t.expression.size(); ++k)
    for (int e : m.ExpressionTargets(name))
      worst = std::max(worst, std::abs(double(fit.photos[k].expression[e]) - t.expression[k][e]));
  return worst;
}

TEST(IctTrackFit, RecoversSyntheticPhotos) {
  ICT_MODEL_OR_SKIP(m);
  constexpr double kNoisePx = 0.5;
  const Truth truth = MakeTruth(m, 5, 1);
  const std::vector<IctObservation> photos = Observe(m, truth, kNoisePx, 2);
  const auto start = std::chrono::steady_clock::now();
  const Result<IctFit> fit = FitIctToLandmarks(m, photos);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  std::printf("%s\n  fit time for 5 photos: %.3f s\n", fit->ToString().c_str(), seconds);
  ASSERT_EQ(fit->photos.size(), 5u);
  // The noise's RMS per landmark (two coordinates) in IOD; a least-squares fit leaves a little less.
  for (size_t k = 0; k < photos.size(); ++k) {
    const IctPhotoFit& p = fit->photos[k];
    const double noise_iod = kNoisePx * std::sqrt(2.0) / p.iod_px;
    EXPECT_LT(p.rms_iod, 1.3 * noise_iod) << "photo " << k;
    EXPECT_GT(p.rms_iod, 0.5 * noise_iod) << "photo " << k;
    EXPECT_EQ(p.landmarks_used, 68);
    const double rot = RotationErrorDeg(p.cam_from_head, truth.cam_from_head[k]);
    std::printf("  photo %zu: rms %.5f IOD (noise %.5f), rotation error %.3f deg\n", k, p.rms_iod, noise_iod,
                rot);
    EXPECT_LT(rot, 3.0) << "photo " << k;
  }
  for (const char* name : {"jawOpen", "mouthSmile_L", "mouthSmile_R"}) {
    const double e = ExpressionError(m, truth, *fit, name);
    std::printf("  %s: largest weight error %.3f\n", name, e);
    EXPECT_LT(e, 0.15) << name;
  }
}

TEST(IctTrackFit, NoiseFreeLandmarksFitExactly) {
  ICT_MODEL_OR_SKIP(m);
  const Truth truth = MakeTruth(m, 4, 3);
  IctFitOptions options;
  options.landmark_sigma_iod = 1e-3;  // the priors barely pull: the truth is the optimum
  const Result<IctFit> fit = FitIctToLandmarks(m, Observe(m, truth, 0.0, 4), options);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  std::printf("%s\n", fit->BriefReport().c_str());
  EXPECT_LT(fit->rms_iod, 1e-4);
  EXPECT_LT(fit->max_iod, 5e-4);
  for (size_t k = 0; k < truth.cam_from_head.size(); ++k)
    EXPECT_LT(RotationErrorDeg(fit->photos[k].cam_from_head, truth.cam_from_head[k]), 0.05) << "photo " << k;
  for (const char* name : {"jawOpen", "mouthSmile_L", "mouthSmile_R", "eyeBlink_L", "eyeBlink_R"})
    EXPECT_LT(ExpressionError(m, truth, *fit, name), 0.01) << name;
}

TEST(IctTrackFit, IsDeterministic) {
  ICT_MODEL_OR_SKIP(m);
  const Truth truth = MakeTruth(m, 3, 5);
  const std::vector<IctObservation> photos = Observe(m, truth, 0.5, 6);
  const Result<IctFit> a = FitIctToLandmarks(m, photos), b = FitIctToLandmarks(m, photos);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->identity, b->identity);
  EXPECT_EQ(a->iterations, b->iterations);
  EXPECT_EQ(a->final_cost, b->final_cost);
  for (size_t k = 0; k < photos.size(); ++k) {
    EXPECT_EQ(a->photos[k].cam_from_head, b->photos[k].cam_from_head);
    EXPECT_EQ(a->photos[k].expression, b->photos[k].expression);
  }
}

// Ceres compares every analytic Jacobian (landmarks, the Gaussian priors, the _L/_R coupling)
// with finite differences at every step and fails the solve on a mismatch. Not the Laplace prior:
// Ceres' Ridders differences start at steps of 0.01 or more, too coarse for its 0.02 smoothing
// (they miss by ~1%; central differences of step 1e-6 agree to 1e-10).
TEST(IctTrackFit, JacobiansMatchFiniteDifferences) {
  ICT_MODEL_OR_SKIP(m);
  const Truth truth = MakeTruth(m, 2, 7);
  IctFitOptions options;
  options.num_identity = 10;
  options.check_gradients = true;
  options.rigid_iterations = 2;
  options.max_iterations = 3;
  const Result<IctFit> fit = FitIctToLandmarks(m, Observe(m, truth, 0.5, 8), options);
  EXPECT_TRUE(fit.ok()) << fit.status().message();
}

// The truth's world frame for the known-camera fit: world_from_head with 0.026 world units per cm
// (the trackers' scale), a turn and a shift; cam_from_world of each photo so that it sees the head
// as the truth's cam_from_head does (the camera frame in world units).
face::Similarity TruthHeadFromWorld() {
  face::Similarity s;  // head_from_world: x_head = s R x_world + t
  s.scale = 1 / 0.026;
  s.rotation = Eigen::AngleAxisd(0.4, Vec3d(0.3, 1, -0.2).normalized()).toRotationMatrix();
  s.translation = Vec3d(1.5, -4, 2);
  return s;
}

std::vector<IctObservation> WithKnownCameras(const Truth& t, std::vector<IctObservation> photos) {
  const face::Similarity h = TruthHeadFromWorld();
  for (size_t k = 0; k < photos.size(); ++k) {
    // camera (world units) = (1 / scale) cam_from_head(head_from_world(x)).
    Mat4d head_from_world = Mat4d::Identity();
    head_from_world.block<3, 3>(0, 0) = h.rotation;
    head_from_world.block<3, 1>(0, 3) = h.translation / h.scale;
    Mat4d m = t.cam_from_head[k] * head_from_world;  // rotation, and the translation in cm / scale
    m.block<3, 1>(0, 3) = t.cam_from_head[k].block<3, 3>(0, 0) * h.translation / h.scale +
                          t.cam_from_head[k].block<3, 1>(0, 3) / h.scale;
    photos[k].cam_from_world = m;
  }
  return photos;
}

// Known cameras: one head pose for all photos. It comes back as the truth's similarity, the
// expressions as the truth's, and each photo's cam_from_head as its camera composed with it.
TEST(IctTrackFit, KnownCamerasPlaceOneHead) {
  ICT_MODEL_OR_SKIP(m);
  const Truth truth = MakeTruth(m, 5, 21);
  const std::vector<IctObservation> photos = WithKnownCameras(truth, Observe(m, truth, 0.5, 22));
  // The cameras are right: the truth's landmarks in the world project onto the observations.
  const face::Similarity h = TruthHeadFromWorld();
  const std::vector<Vec3f> lm = m.Landmarks(m.Mesh(truth.identity, truth.expression[1]));
  const Camera camera(photos[1].intrinsics, photos[1].cam_from_world->inverse());
  EXPECT_LT(
      (camera.Project(h.ApplyInverse(lm[30].cast<double>()))->uv - photos[1].landmarks[30].cast<double>())
          .norm(),
      3.0);
  const Result<IctFit> fit = FitIctToLandmarks(m, photos, IctFitOptions::ForPhotos());
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  ASSERT_TRUE(fit->head_from_world.has_value());
  const face::Similarity& got = *fit->head_from_world;
  std::printf("[ known cameras ] %s; truth %s\n", fit->BriefReport().c_str(), h.ToString().c_str());
  // The scale trades against the identity's size (a larger head farther off): a few percent.
  EXPECT_NEAR(got.scale / h.scale, 1.0, 0.08);
  EXPECT_LT(Eigen::AngleAxisd(got.rotation.transpose() * h.rotation).angle() * 180 / M_PI, 1.5);
  // The fitted head lands where the truth's is, in the world: every landmark of every photo within
  // 0.01 world units (4 mm) RMS.
  double sum2 = 0;
  int count = 0;
  for (size_t k = 0; k < photos.size(); ++k) {
    const std::vector<Vec3f> fitted = m.Landmarks(m.Mesh(fit->identity, fit->photos[k].expression));
    const std::vector<Vec3f> true_lm = m.Landmarks(m.Mesh(truth.identity, truth.expression[k]));
    for (int i = 17; i < 68; ++i, ++count)
      sum2 += (got.ApplyInverse(fitted[i].cast<double>()) - h.ApplyInverse(true_lm[i].cast<double>()))
                  .squaredNorm();
  }
  const double world_rms = std::sqrt(sum2 / count);
  std::printf("[ known cameras ] inner landmarks in the world: RMS %.4f units (%.2f cm)\n", world_rms,
              world_rms * h.scale);
  EXPECT_LT(world_rms, 0.01);
  EXPECT_LT(fit->rms_iod, 0.01);
  EXPECT_LT(ExpressionError(m, truth, *fit, "jawOpen"), 0.1);
  EXPECT_LT(ExpressionError(m, truth, *fit, "mouthSmile"), 0.15);
  for (size_t k = 0; k < photos.size(); ++k) {
    Mat4d head_from_world_m = Mat4d::Identity();
    head_from_world_m.block<3, 3>(0, 0) = got.rotation * got.scale;
    head_from_world_m.block<3, 1>(0, 3) = got.translation;
    // cam_from_head (cm) = (1 / scale of world per cm) camera o world_from_head: compare directions.
    EXPECT_LT(RotationErrorDeg(fit->photos[k].cam_from_head, truth.cam_from_head[k]), 1.0) << k;
  }
}

TEST(IctTrackFit, KnownCameraJacobiansMatchFiniteDifferences) {
  ICT_MODEL_OR_SKIP(m);
  const Truth truth = MakeTruth(m, 3, 27);
  IctFitOptions options;
  options.num_identity = 10;
  options.check_gradients = true;
  options.rigid_iterations = 2;
  options.max_iterations = 3;
  const Result<IctFit> fit =
      FitIctToLandmarks(m, WithKnownCameras(truth, Observe(m, truth, 0.5, 24)), options);
  EXPECT_TRUE(fit.ok()) << fit.status().message();
}

TEST(IctTrackFit, KnownCamerasMustBeAllAndTellTheScale) {
  ICT_MODEL_OR_SKIP(m);
  const Truth truth = MakeTruth(m, 3, 25);
  std::vector<IctObservation> photos = WithKnownCameras(truth, Observe(m, truth, 0.5, 26));
  std::vector<IctObservation> some = photos;
  some[1].cam_from_world.reset();
  EXPECT_NE(FitIctToLandmarks(m, some).status().message().find("all or none"), std::string::npos);
  const std::vector<IctObservation> one = {photos[0]};
  EXPECT_NE(FitIctToLandmarks(m, one).status().message().find("do not determine the head's scale"),
            std::string::npos);
  some = photos;
  (*some[2].cam_from_world)(0, 0) = 2;
  EXPECT_NE(FitIctToLandmarks(m, some).status().message().find("photo 2: cam_from_world is not a rigid"),
            std::string::npos);
}

// Missing landmarks (weight 0, NaN positions), a whole eye among them: the inter-ocular distance
// then comes from the initial pose.
TEST(IctTrackFit, IgnoresMissingLandmarks) {
  ICT_MODEL_OR_SKIP(m);
  const Truth truth = MakeTruth(m, 3, 9);
  std::vector<IctObservation> photos = Observe(m, truth, 0.5, 10);
  for (IctObservation& o : photos) o.weights.assign(68, 1.f);
  for (int i : {0, 1, 2, 3, 42, 43, 44, 45, 46, 47}) {
    photos[2].weights[i] = 0;
    photos[2].landmarks[i] = Vec2f::Constant(std::numeric_limits<float>::quiet_NaN());
  }
  photos[1].weights[30] = 0;
  photos[1].landmarks[30] += Vec2f(200, 200);  // far off, but missing
  const Result<IctFit> fit = FitIctToLandmarks(m, photos);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  std::printf("%s\n", fit->ToString().c_str());
  EXPECT_EQ(fit->photos[1].landmarks_used, 67);
  EXPECT_EQ(fit->photos[2].landmarks_used, 58);
  EXPECT_NEAR(fit->photos[2].iod_px, fit->photos[1].iod_px, 0.3 * fit->photos[1].iod_px);
  for (size_t k = 0; k < photos.size(); ++k) {
    EXPECT_LT(fit->photos[k].rms_iod, 0.02) << "photo " << k;
    EXPECT_LT(RotationErrorDeg(fit->photos[k].cam_from_head, truth.cam_from_head[k]), 3.0) << "photo " << k;
  }
}

// Two negative focal lengths are the same camera turned 180 degrees about its axis
// (math/camera.h): the head's pose relative to the camera frame is the same.
TEST(IctTrackFit, HandlesSignedFocalLengths) {
  ICT_MODEL_OR_SKIP(m);
  const Truth truth = MakeTruth(m, 3, 11);
  std::vector<IctObservation> photos = Observe(m, truth, 0.0, 12);
  for (IctObservation& o : photos) {
    o.intrinsics.fl_x = o.intrinsics.fl_y = -1000;
    for (Vec2f& p : o.landmarks) p = Vec2f(512, 512) - p;  // turned about the principal point
  }
  const Result<IctFit> fit = FitIctToLandmarks(m, photos);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  for (size_t k = 0; k < photos.size(); ++k)
    EXPECT_LT(RotationErrorDeg(fit->photos[k].cam_from_head, truth.cam_from_head[k]), 3.0) << "photo " << k;
}

// The priors do what they say: a tight _L/_R coupling makes the halves equal, a Laplace prior
// leaves more weights at exactly 0.
TEST(IctTrackFit, PriorsShapeTheExpressions) {
  ICT_MODEL_OR_SKIP(m);
  const Truth truth = MakeTruth(m, 3, 15);
  const std::vector<IctObservation> photos = Observe(m, truth, 0.5, 16);
  const auto zeros = [](const IctFit& fit) {
    int n = 0;
    for (const IctPhotoFit& p : fit.photos)
      for (float w : p.expression) n += w == 0.f;
    return n;
  };
  const Result<IctFit> plain = FitIctToLandmarks(m, photos);
  IctFitOptions options;
  options.symmetry_sigma = 1e-3;
  const Result<IctFit> coupled = FitIctToLandmarks(m, photos, options);
  options = {};
  options.expression_prior_laplace = 3;
  const Result<IctFit> sparse = FitIctToLandmarks(m, photos, options);
  ASSERT_TRUE(plain.ok() && coupled.ok() && sparse.ok());
  double asymmetry = 0;
  for (const IctPhotoFit& p : coupled->photos)
    for (int e = 0; e < m.num_expressions(); ++e) {
      const std::string& name = m.expression_names()[e];
      if (name.size() < 2 || name.substr(name.size() - 2) != "_L" || name.rfind("eyeLook", 0) == 0) continue;
      const int right = m.ExpressionIndex(name.substr(0, name.size() - 2) + "_R");
      asymmetry = std::max(asymmetry, std::abs(double(p.expression[e]) - p.expression[right]));
    }
  std::printf("largest |L - R| coupled: %.4f; weights at 0: %d plain, %d with the Laplace prior\n", asymmetry,
              zeros(*plain), zeros(*sparse));
  EXPECT_LT(asymmetry, 0.01);
  EXPECT_GT(zeros(*sparse), zeros(*plain) + 20);
  EXPECT_LT(sparse->rms_iod, 0.02);
}

// The error of a fit on `photos` after `edit`; "" when it succeeds.
template <typename Edit>
std::string ErrorAfter(const face::IctModel& m, Edit edit, IctFitOptions options = {}) {
  std::vector<IctObservation> photos = Observe(m, MakeTruth(m, 3, 13), 0.5, 14);
  edit(photos);
  const Result<IctFit> fit = FitIctToLandmarks(m, photos, options);
  return fit.ok() ? "" : fit.status().message();
}

TEST(IctTrackFit, RejectsBadInput) {
  ICT_MODEL_OR_SKIP(m);
  using Photos = std::vector<IctObservation>;
  const auto expect = [&](const std::string& error, const std::string& fragment) {
    EXPECT_NE(error.find(fragment), std::string::npos) << "error: \"" << error << "\", expected " << fragment;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  };
  expect(ErrorAfter(m, [](Photos& p) { p.clear(); }), "no observations");
  expect(ErrorAfter(m, [](Photos& p) { p[1].landmarks.pop_back(); }), "photo 1: 67 landmarks, expected 68");
  expect(ErrorAfter(m, [](Photos& p) { p[2].weights.assign(5, 1.f); }), "photo 2: 5 weights");
  expect(ErrorAfter(m, [](Photos& p) { p[0].landmarks[7].x() = NAN; }), "photo 0: landmark 7 is not finite");
  expect(ErrorAfter(m, [](Photos& p) { p[1].landmarks[3].y() = INFINITY; }),
         "photo 1: landmark 3 is not finite");
  expect(ErrorAfter(m, [](Photos& p) { p[2].weights.assign(68, -1.f); }), "photo 2: landmark 0 has weight");
  expect(ErrorAfter(m, [](Photos& p) { p[1].weights.assign(68, NAN); }), "photo 1: landmark 0 has weight");
  expect(ErrorAfter(m, [](Photos& p) { p[1].weights.assign(68, 0.f); }),
         "photo 1: every landmark is missing");
  expect(ErrorAfter(m,
                    [](Photos& p) {
                      p[2].weights.assign(68, 0.f);
                      for (int i = 30; i < 33; ++i) p[2].weights[i] = 1;
                    }),
         "photo 2: only 3 landmarks");
  expect(ErrorAfter(m, [](Photos& p) { p[0].intrinsics.fl_x = 0; }), "photo 0: intrinsics");
  IctFitOptions options;
  options.num_identity = m.num_identities() + 1;
  expect(ErrorAfter(
             m, [](Photos&) {}, options),
         "exceeds the model's");
  options = {};
  options.symmetry_sigma = 0;
  expect(ErrorAfter(
             m, [](Photos&) {}, options),
         "symmetry_sigma");
}

TEST(IctTrackFit, OptionsValidate) {
  EXPECT_TRUE(IctFitOptions{}.Validate().ok());
  IctFitOptions o;
  o.symmetry_sigma = std::numeric_limits<double>::infinity();  // no coupling
  EXPECT_TRUE(o.Validate().ok());
  o = {};
  o.jaw_line_weight = 1.5;
  EXPECT_FALSE(o.Validate().ok());
  o = {};
  o.landmark_sigma_iod = NAN;
  EXPECT_FALSE(o.Validate().ok());
  o = {};
  o.num_identity = 0;
  EXPECT_FALSE(o.Validate().ok());
  EXPECT_NE(IctFitOptions{}.ToString().find("num_identity=40"), std::string::npos);
}

}  // namespace
}  // namespace icef::face
