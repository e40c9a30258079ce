#include "icef/face/face_fit.h"

#include <gtest/gtest.h>

#include <cmath>

#include "icef/core/rng.h"
#include "icef/face/expression.h"
#include "icef/face/face_model.h"

namespace icef::face {
namespace {

// A head that is not the average one, in a world frame that is not the head frame.
ShapeParams KnownShape() {
  ShapeParams p;
  p.jaw_width = 1.1f;
  p.chin_length = 0.9f;
  p.nose_length = 1.12f;
  p.eye_spacing = 0.95f;
  p.mouth_width = 1.08f;
  p.brow_height = 1.15f;
  p.lip_thickness = 0.9f;
  return p;
}

Similarity KnownSimilarity() {
  Similarity s;
  s.scale = 1.6;  // world units are smaller than head units
  s.rotation = Eigen::AngleAxisd(0.35, Vec3d(0.2, 1.0, -0.1).normalized()).toRotationMatrix();
  s.translation = Vec3d(0.05, -0.1, 0.2);
  return s;
}

std::vector<std::vector<float>> Expressions(int k, uint64_t seed) {
  Rng rng(seed, StreamId("fit_expressions"));
  std::vector<std::vector<float>> e;
  for (int i = 0; i < k; ++i) {
    std::vector<float> b(kNumExpressions, 0.f);
    for (float& v : b) v = rng.UniformDouble() < 0.4 ? static_cast<float>(rng.Uniform(0.0, 0.8)) : 0.f;
    e.push_back(b);
  }
  return e;
}

// Landmarks of the known head in the world frame, with Gaussian noise of `noise_iod` IOD per axis.
std::vector<FitFrame> Frames3d(const FaceModel& truth, const Similarity& s, int k, double noise_iod,
                               uint64_t seed) {
  const double iod = InterOcularDistance(truth.NeutralLandmarks());
  Rng rng(seed, StreamId("fit_noise"));
  std::vector<FitFrame> frames;
  for (const std::vector<float>& beta : Expressions(k, seed)) {
    FitFrame f;
    f.expression = beta;
    const auto lm = truth.Landmarks(truth.Prepare(beta));
    std::vector<Vec3f> world;
    for (const Vec3f& p : lm) {
      Vec3d x = p.cast<double>() + noise_iod * iod * Vec3d(rng.Normal(), rng.Normal(), rng.Normal());
      world.push_back(s.ApplyInverse(x).cast<float>());
    }
    f.landmarks_3d = world;
    frames.push_back(std::move(f));
  }
  return frames;
}

void ExpectSimilarityNear(const Similarity& got, const Similarity& want, double tol_scale, double tol_deg,
                          double tol_translation) {
  EXPECT_NEAR(got.scale / want.scale, 1.0, tol_scale);
  const double angle = Eigen::AngleAxisd(got.rotation * want.rotation.transpose()).angle() * 180.0 / M_PI;
  EXPECT_LT(angle, tol_deg);
  EXPECT_LT((got.translation - want.translation).norm(), tol_translation);
}

TEST(FaceFitTest, RecoversShapeAndSimilarityFromNoisy3dLandmarks) {
  const FaceModel truth(KnownShape());
  const Similarity s = KnownSimilarity();
  const std::vector<FitFrame> frames = Frames3d(truth, s, 5, 0.01, 1);
  const Result<FaceFit> fit = FitFaceModel(frames);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_LT(fit->rms_iod, 0.03) << fit->BriefReport();
  ExpectSimilarityNear(fit->head_from_world, s, 0.02, 1.5, 0.02);
  // The shape scales the landmarks see directly.
  const ShapeParams want = KnownShape();
  EXPECT_NEAR(fit->shape.eye_spacing, want.eye_spacing, 0.04);
  EXPECT_NEAR(fit->shape.mouth_width, want.mouth_width, 0.06);
  EXPECT_NEAR(fit->shape.nose_length, want.nose_length, 0.06);
  EXPECT_NEAR(fit->shape.brow_height, want.brow_height, 0.08);
  EXPECT_NEAR(fit->shape.jaw_width, want.jaw_width, 0.08);
  // And the fitted head's landmarks match the true ones at a new, far expression.
  std::vector<float> far(kNumExpressions, 0.f);
  far[kJawOpen] = 1.4f, far[kSmileLeft] = 1.2f, far[kBrowRaiseRight] = 1.3f;
  const FaceModel fitted(fit->shape);
  const auto a = fitted.Landmarks(fitted.Prepare(far));
  const auto b = truth.Landmarks(truth.Prepare(far));
  const double iod = InterOcularDistance(truth.NeutralLandmarks());
  double rms = 0;
  for (int i = 0; i < 68; ++i) rms += (a[i] - b[i]).squaredNorm();
  EXPECT_LT(std::sqrt(rms / 68) / iod, 0.03);
}

// A subject with its own expression style, seen in frames that use the styled expressions (and never
// cheek_puff).
TEST(FaceFitTest, RecoversTheExpressionStyleOfTheExpressionsItSees) {
  ExpressionStyle style;
  style.jaw_gain = 0.75f;
  style.smile_gain = {1.f, 1.2f};
  style.brow_raise_gain = {0.8f, 1.f};
  style.lip_press_gain = 1.25f;
  const FaceModel truth(KnownShape(), style);
  const Similarity s = KnownSimilarity();
  std::vector<FitFrame> frames = Frames3d(truth, s, 5, 0.005, 3);
  const std::vector<std::vector<float>> seen = {{0.6f, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
                                                {0.25f, 0.5f, 0, 0, 0, 0, 0, 0, 0, 0, 0},
                                                {0, 0, 0, 0, 0.5f, 0, 0.55f, 0, 0, 0, 0},
                                                {0, 0.6f, 0, 0, 0, 0, 0, 0, 0.3f, 0, 0},
                                                {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}};
  const double iod = InterOcularDistance(truth.NeutralLandmarks());
  Rng rng(4, StreamId("fit_noise"));
  for (size_t k = 0; k < frames.size(); ++k) {  // the same frames' landmarks at these expressions
    frames[k].expression = seen[k];
    const auto lm = truth.Landmarks(truth.Prepare(seen[k]));
    for (int i = 0; i < 68; ++i)
      (*frames[k].landmarks_3d)[i] =
          s.ApplyInverse(lm[i].cast<double>() + 0.005 * iod * Vec3d(rng.Normal(), rng.Normal(), rng.Normal()))
              .cast<float>();
  }
  FaceFitOptions options;
  const Result<FaceFit> generic = FitFaceModel(frames, options);
  ASSERT_TRUE(generic.ok()) << generic.status().message();
  EXPECT_TRUE(generic->style.IsGeneric());
  options.fit_style = true;
  const Result<FaceFit> fit = FitFaceModel(frames, options);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_LT(fit->rms_iod, generic->rms_iod) << fit->BriefReport();
  EXPECT_NEAR(fit->style.jaw_gain, 0.75f, 0.05f) << fit->style.ToString();
  EXPECT_NEAR(fit->style.smile_gain[1], 1.2f, 0.1f) << fit->style.ToString();
  // Brows and lips move fewer landmarks less far: the prior holds them back more.
  EXPECT_NEAR(fit->style.brow_raise_gain[0], 0.8f, 0.1f) << fit->style.ToString();
  EXPECT_NEAR(fit->style.lip_press_gain, 1.25f, 0.15f) << fit->style.ToString();
  // No frame puffs the cheeks or smiles on the right: those fields keep the generic style's value.
  EXPECT_NEAR(fit->style.cheek_puff_gain, 1.f, 1e-4f);
  EXPECT_NEAR(fit->style.smile_gain[0], 1.f, 1e-4f);
  EXPECT_NE(fit->BriefReport().find("jaw_gain"), std::string::npos) << fit->BriefReport();
  EXPECT_FALSE(fit->style_rejected);
  EXPECT_GT(fit->style_f, 3.0);
  // Far from the frames' expressions the fitted style's landmarks are nearer the truth's.
  std::vector<float> far(kNumExpressions, 0.f);
  far[kJawOpen] = 1.4f, far[kSmileLeft] = 1.2f, far[kBrowRaiseRight] = 1.3f;
  const auto truth_far = truth.Landmarks(truth.Prepare(far));
  auto rms_at_far = [&](const FaceFit& f) {
    const FaceModel m(f.shape, f.style);
    const auto lm = m.Landmarks(m.Prepare(far));
    double sum = 0;
    for (int i = 0; i < 68; ++i) sum += (lm[i] - truth_far[i]).squaredNorm();
    return std::sqrt(sum / 68) / iod;
  };
  EXPECT_LT(rms_at_far(*fit), 0.5 * rms_at_far(*generic));
}

// Landmarks of a head in the generic style (a tracked dataset's are the generic face model's own):
// a fitted style explains them no better, and the fit keeps the generic style.
TEST(FaceFitTest, KeepsTheGenericStyleWhenTheLandmarksShowNoOther) {
  const FaceModel truth(KnownShape());
  const std::vector<FitFrame> frames = Frames3d(truth, KnownSimilarity(), 5, 0.005, 5);
  FaceFitOptions options;
  options.fit_style = true;
  const Result<FaceFit> fit = FitFaceModel(frames, options);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_TRUE(fit->style_rejected) << fit->BriefReport();
  EXPECT_LT(fit->style_f, 3.0);
  EXPECT_TRUE(fit->style.IsGeneric());
  EXPECT_NE(fit->BriefReport().find("expression style: generic"), std::string::npos) << fit->BriefReport();
  const Result<FaceFit> plain = FitFaceModel(frames);  // the same fit as without fit_style
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(fit->rms_iod, plain->rms_iod);
  EXPECT_EQ(fit->shape.ToArray(), plain->shape.ToArray());
}

TEST(FaceFitTest, OutlierLandmarksAreDropped) {
  const FaceModel truth(KnownShape());
  const Similarity s = KnownSimilarity();
  std::vector<FitFrame> frames = Frames3d(truth, s, 4, 0.005, 2);
  (*frames[0].landmarks_3d)[8] += Vec3f(0.2f, 0.f, 0.f);  // a detector gone wrong
  (*frames[2].landmarks_3d)[48] += Vec3f(0.f, 0.15f, 0.05f);
  const Result<FaceFit> fit = FitFaceModel(frames);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_LE(fit->landmarks_used, fit->landmarks_total - 2);
  EXPECT_LT(fit->rms_iod, 0.03) << fit->BriefReport();
  ExpectSimilarityNear(fit->head_from_world, s, 0.02, 1.5, 0.02);
}

TEST(FaceFitTest, RecoversTheHeadFrom2dLandmarksAndCameras) {
  const FaceModel truth(KnownShape());
  const Similarity s = KnownSimilarity();
  std::vector<FitFrame> frames;
  const auto exprs = Expressions(5, 3);
  for (int k = 0; k < 5; ++k) {
    Intrinsics in;
    in.width = in.height = 256;
    in.fl_x = in.fl_y = 400;
    in.cx = in.cy = 128;
    // Cameras around the head's front (head +z), in world coordinates.
    const double yaw = 0.5 * (k - 2) / 2.0;
    const Vec3d eye_head(1.6 * std::sin(yaw), 0.1 * (k % 2), 1.6 * std::cos(yaw));
    const Camera cam = Camera::LookAt(in, s.ApplyInverse(eye_head), s.ApplyInverse(Vec3d(0, -0.05, 0)),
                                      s.rotation.transpose() * Vec3d::UnitY());
    FitFrame f;
    f.expression = exprs[k];
    std::vector<Vec2f> px;
    for (const Vec3f& p : truth.Landmarks(truth.Prepare(exprs[k])))
      px.push_back(cam.Project(s.ApplyInverse(p.cast<double>()))->uv.cast<float>());
    f.landmarks_2d = px;
    f.camera = cam;
    frames.push_back(std::move(f));
  }
  const Result<FaceFit> fit = FitFaceModel(frames);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_LT(fit->rms_iod, 0.02) << fit->BriefReport();
  ExpectSimilarityNear(fit->head_from_world, s, 0.03, 2.0, 0.03);
}

TEST(FaceFitTest, BadInputIsAnError) {
  EXPECT_FALSE(FitFaceModel({}).ok());
  FitFrame f;
  f.expression.assign(kNumExpressions, 0.f);
  std::vector<FitFrame> one = {f};
  EXPECT_NE(FitFaceModel(one).status().message().find("no landmarks"), std::string::npos);
  one[0].landmarks_2d = std::vector<Vec2f>(68, Vec2f(1, 1));
  EXPECT_NE(FitFaceModel(one).status().message().find("camera"), std::string::npos);
  one[0].landmarks_2d.reset();
  one[0].landmarks_3d = std::vector<Vec3f>(67, Vec3f::Zero());
  EXPECT_NE(FitFaceModel(one).status().message().find("68"), std::string::npos);
  one[0].landmarks_3d = std::vector<Vec3f>(68, Vec3f::Zero());
  one[0].expression[2] = -1.f;
  EXPECT_FALSE(FitFaceModel(one).ok());
  one[0].expression.pop_back();
  EXPECT_FALSE(FitFaceModel(one).ok());
}

}  // namespace
}  // namespace icef::face
