#include "icef/synth/photo_set.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "icef/face/expression.h"
#include "icef/io/atomic_file.h"
#include "icef/synth/head_model.h"
#include "icef/synth/synthesize.h"

namespace icef::synth {
namespace {

namespace fs = std::filesystem;

PhotoSetOptions Small() {
  PhotoSetOptions o;
  o.identity_seed = 3;
  o.num_photos = 3;
  o.width = 160;
  o.height = 200;
  return o;
}

// The small set rendered once (rendering is the slow part of these tests).
const std::vector<SynthPhoto>& SmallPhotos() {
  static const std::vector<SynthPhoto> photos = [] {
    Result<std::vector<SynthPhoto>> r = RenderPhotoSet(Small(), Executor(2));
    EXPECT_TRUE(r.ok()) << r.status().message();
    return r.ok() ? *r : std::vector<SynthPhoto>();
  }();
  return photos;
}

TEST(PhotoSetTest, ValidateRejectsBadOptions) {
  EXPECT_TRUE(PhotoSetOptions().Validate().ok()) << PhotoSetOptions().Validate().message();
  EXPECT_TRUE(Small().Validate().ok()) << Small().Validate().message();
  auto rejects = [](auto edit, const std::string& what) {
    PhotoSetOptions o = Small();
    edit(o);
    const Status s = o.Validate();
    EXPECT_FALSE(s.ok()) << what;
    EXPECT_NE(s.message().find(what), std::string::npos) << s.message();
  };
  rejects([](PhotoSetOptions& o) { o.num_photos = 0; }, "num_photos");
  rejects([](PhotoSetOptions& o) { o.width = 4; }, "width x height");
  rejects([](PhotoSetOptions& o) { o.focal_scale = 0.0; }, "focal_scale");
  rejects([](PhotoSetOptions& o) { o.max_yaw_deg = -1.0; }, "max_yaw_deg");
  rejects([](PhotoSetOptions& o) { o.max_pitch_deg = 90.0; }, "max_pitch_deg");
  rejects([](PhotoSetOptions& o) { o.max_roll_deg = NAN; }, "max_roll_deg");
  rejects([](PhotoSetOptions& o) { o.min_head_fraction = 0.0; }, "head fraction");
  rejects([](PhotoSetOptions& o) { o.min_head_fraction = 0.7; }, "head fraction");  // min > max
  rejects([](PhotoSetOptions& o) { o.max_head_fraction = 1.2; }, "head fraction");
  rejects([](PhotoSetOptions& o) { o.max_offset_fraction = -0.1; }, "max_offset_fraction");
  rejects([](PhotoSetOptions& o) { o.max_offset_fraction = 0.3; }, "max_head_fraction / 2");  // off the top
  rejects([](PhotoSetOptions& o) { o.width = 100; }, "would not fit across");
  rejects([](PhotoSetOptions& o) { o.max_expression = -0.5; }, "max_expression");
  rejects([](PhotoSetOptions& o) { o.render.supersample = 0; }, "render");
  // A camera inside the head's box is refused by the plan.
  PhotoSetOptions o = Small();
  o.focal_scale = 0.3;
  EXPECT_FALSE(PlanPhotoSet(o).ok());
}

TEST(PhotoSetTest, PlanDrawsPosesInRangeAndIsAPureFunctionOfTheOptions) {
  PhotoSetOptions o;
  o.num_photos = 40;
  const Result<std::vector<PhotoPlan>> plans = PlanPhotoSet(o);
  ASSERT_TRUE(plans.ok()) << plans.status().message();
  ASSERT_EQ(plans->size(), 40u);
  const Result<std::vector<PhotoPlan>> again = PlanPhotoSet(o);
  ASSERT_TRUE(again.ok());
  double max_yaw = 0.0;
  for (size_t i = 0; i < plans->size(); ++i) {
    const PhotoPlan& p = (*plans)[i];
    EXPECT_EQ(p.camera.world_from_cam(), (*again)[i].camera.world_from_cam());
    EXPECT_LE(std::abs(p.yaw_deg), o.max_yaw_deg);
    EXPECT_LE(std::abs(p.pitch_deg), o.max_pitch_deg);
    EXPECT_LE(std::abs(p.roll_deg), o.max_roll_deg);
    EXPECT_GE(p.head_fraction, o.min_head_fraction);
    EXPECT_LE(p.head_fraction, o.max_head_fraction);
    EXPECT_LE(std::abs(p.offset_px.x()), o.max_offset_fraction * o.width);
    EXPECT_LE(std::abs(p.offset_px.y()), o.max_offset_fraction * o.height);
    max_yaw = std::max(max_yaw, std::abs(p.yaw_deg));
    // The face direction (+z of the head) seen from the camera is the drawn yaw/pitch.
    const Vec3d face_cam = p.camera.cam_from_world().block<3, 3>(0, 0) * Vec3d::UnitZ();
    const Vec3d unrolled = Eigen::AngleAxisd(-p.roll_deg * M_PI / 180.0, Vec3d::UnitZ()) * face_cam;
    EXPECT_NEAR(std::atan2(unrolled.x(), unrolled.z()) * 180.0 / M_PI, p.yaw_deg, 1e-6);
    EXPECT_NEAR(std::asin(unrolled.y()) * 180.0 / M_PI, p.pitch_deg, 1e-6);
    float sum = 0.f;
    for (float b : p.expression) {
      EXPECT_GE(b, 0.f);
      EXPECT_LE(b, o.max_expression + 1e-6);
      sum += b;
    }
    if (i == 0)
      EXPECT_EQ(sum, 0.f) << "photo 0 is neutral";
    else
      EXPECT_GT(sum, 0.f) << "photo " << i;
  }
  EXPECT_GT(max_yaw, 0.6 * o.max_yaw_deg);  // the range is used
  o.identity_seed = 2;
  EXPECT_NE(PlanPhotoSet(o)->at(1).camera.world_from_cam(), plans->at(1).camera.world_from_cam());
}

TEST(PhotoSetTest, RenderIsDeterministicWhateverTheThreadCount) {
  const std::vector<SynthPhoto>& photos = SmallPhotos();
  ASSERT_EQ(photos.size(), 3u);
  const Result<std::vector<SynthPhoto>> again = RenderPhotoSet(Small(), Executor(1));
  ASSERT_TRUE(again.ok()) << again.status().message();
  for (size_t i = 0; i < photos.size(); ++i) {
    EXPECT_EQ(photos[i].image.pixels, (*again)[i].image.pixels) << "photo " << i;
    EXPECT_EQ(photos[i].alpha.pixels, (*again)[i].alpha.pixels) << "photo " << i;
    EXPECT_EQ(photos[i].landmarks_2d, (*again)[i].landmarks_2d) << "photo " << i;
  }
}

TEST(PhotoSetTest, HeadHasTheDrawnSizeAndLandmarksLieInTheImage) {
  const PhotoSetOptions o = Small();
  for (const SynthPhoto& p : SmallPhotos()) {
    SCOPED_TRACE(p.ToString());
    ASSERT_EQ(p.image.channels, 3);
    ASSERT_EQ(p.alpha.channels, 1);
    ASSERT_EQ(p.image.width, o.width);
    ASSERT_EQ(p.image.height, o.height);
    int top = o.height, covered = 0, partial = 0;
    for (int y = 0; y < o.height; ++y) {
      for (int x = 0; x < o.width; ++x) {
        const float a = p.alpha.At(x, y, 0);
        ASSERT_GE(a, 0.f);
        ASSERT_LE(a, 1.f);
        if (a > 0.5f) top = std::min(top, y), ++covered;
        if (a > 0.f && a < 1.f) ++partial;
      }
    }
    const double fraction = double(covered) / (o.width * o.height);
    EXPECT_GT(fraction, 0.05);
    EXPECT_LT(fraction, 0.6);
    EXPECT_GT(partial, 0) << "antialiased edges";
    ASSERT_EQ(p.landmarks_2d.size(), 68u);
    for (const Vec2f& l : p.landmarks_2d) {
      EXPECT_GT(l.x(), 0.f);
      EXPECT_LT(l.x(), float(o.width));
      EXPECT_GT(l.y(), 0.f);
      EXPECT_LT(l.y(), float(o.height));
    }
    // Crown (the mask's top row) to chin (landmark 8): the drawn head fraction, within what pose and
    // perspective change.
    const double head = (p.landmarks_2d[8].y() - top) / o.height;
    EXPECT_GT(head, 0.8 * p.head_fraction);
    EXPECT_LT(head, 1.2 * p.head_fraction);
    EXPECT_GE(head, 0.8 * o.min_head_fraction);
    EXPECT_LE(head, 1.2 * o.max_head_fraction);
    // The nose tip (landmark 30) is in front of the rest of the face: covered.
    const Vec2f nose = p.landmarks_2d[30];
    EXPECT_EQ(p.alpha.At(int(nose.x()), int(nose.y()), 0), 1.f);
  }
}

TEST(PhotoSetTest, CameraIsAPinholeAtTheImageCentreAndProjectsTheLandmarks) {
  const PhotoSetOptions o = Small();
  const HeadModel head(PhotoSetIdentity(o));
  for (const SynthPhoto& p : SmallPhotos()) {
    EXPECT_TRUE(ValidateRigid(p.camera.world_from_cam(), 1e-9).ok());
    const Intrinsics& in = p.camera.intrinsics();
    EXPECT_EQ(in.cx, 0.5 * o.width);
    EXPECT_EQ(in.cy, 0.5 * o.height);
    EXPECT_EQ(in.fl_x, in.fl_y);
    EXPECT_EQ(in.fl_x, o.focal_scale * std::max(o.width, o.height));
    ASSERT_EQ(p.expression.size(), size_t(face::kNumExpressions));
    const auto points = head.face().Landmarks(head.face().Prepare(p.expression));
    ASSERT_EQ(p.landmarks_3d.size(), 68u);
    int visible = 0;
    for (int k = 0; k < 68; ++k) {
      EXPECT_EQ(p.landmarks_3d[k], points[k]);
      const auto projection = p.camera.Project(points[k].cast<double>());
      ASSERT_TRUE(projection.has_value());
      EXPECT_NEAR(projection->uv.x(), p.landmarks_2d[k].x(), 1e-3);
      EXPECT_NEAR(projection->uv.y(), p.landmarks_2d[k].y(), 1e-3);
      visible += p.landmarks_visible[k];
    }
    EXPECT_GT(visible, 40);
  }
}

TEST(PhotoSetTest, BackgroundIsTexturedAndDiffersBetweenPhotos) {
  const PhotoSetOptions o = Small();
  const std::vector<SynthPhoto>& photos = SmallPhotos();
  std::vector<Vec3f> means;
  for (const SynthPhoto& p : photos) {
    // Statistics of the uncovered pixels: far from a flat colour.
    Vec3d sum = Vec3d::Zero(), sum2 = Vec3d::Zero();
    int n = 0;
    for (int y = 0; y < o.height; ++y)
      for (int x = 0; x < o.width; ++x)
        if (p.alpha.At(x, y, 0) == 0.f) {
          const Vec3d c = p.image.Rgb(x, y).cast<double>();
          sum += c, sum2 += c.cwiseProduct(c), ++n;
        }
    ASSERT_GT(n, 1000);
    const Vec3d mean = sum / n;
    const Vec3d var = sum2 / n - mean.cwiseProduct(mean);
    EXPECT_GT(std::sqrt(var.sum()), 0.05) << "background std over RGB";
    means.push_back(mean.cast<float>());
  }
  EXPECT_GT((means[0] - means[1]).norm() + (means[1] - means[2]).norm(), 0.02);
  // Uncovered pixels are the background itself, covered ones are not.
  const uint64_t seed = 12345;
  const Image a = PhotoBackground(seed, 0, 64, 48, Executor(1));
  const Image b = PhotoBackground(seed, 0, 64, 48, Executor(2));
  EXPECT_EQ(a.pixels, b.pixels);
  EXPECT_NE(a.pixels, PhotoBackground(seed, 1, 64, 48).pixels);
  PhotoSetOptions custom = Small();
  custom.num_photos = 1;
  custom.width = 96;
  custom.height = 120;
  custom.render.supersample = 1;
  custom.background_seed = seed;
  const Result<std::vector<SynthPhoto>> one = RenderPhotoSet(custom, Executor(2));
  ASSERT_TRUE(one.ok()) << one.status().message();
  const Image bg = PhotoBackground(seed, 0, custom.width, custom.height);
  int background = 0, differs = 0;
  for (int y = 0; y < custom.height; ++y)
    for (int x = 0; x < custom.width; ++x) {
      const float alpha = (*one)[0].alpha.At(x, y, 0);
      if (alpha == 0.f) {
        ++background;
        for (int c = 0; c < 3; ++c) ASSERT_EQ((*one)[0].image.At(x, y, c), bg.At(x, y, c));
      } else if (alpha == 1.f) {
        differs += ((*one)[0].image.Rgb(x, y) - bg.Rgb(x, y)).norm() > 1e-3f;
      }
    }
  EXPECT_GT(background, 0);
  EXPECT_GT(differs, 0);
}

TEST(PhotoSetTest, WritesPhotosAlphaTruthAndStyle) {
  const fs::path dir = fs::temp_directory_path() / ("icef_photo_set_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const PhotoSetOptions o = Small();
  ASSERT_TRUE(WritePhotoSet(o, SmallPhotos(), dir).ok());
  for (int i = 0; i < o.num_photos; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "%03d.png", i);
    const Result<Image> image = ReadImage(dir / "photos" / ("photo_" + std::string(name)));
    ASSERT_TRUE(image.ok()) << image.status().message();
    EXPECT_EQ(image->channels, 3);
    EXPECT_EQ(image->width, o.width);
    EXPECT_EQ(image->height, o.height);
    const Result<Image> alpha = ReadImage(dir / "truth" / ("alpha_" + std::string(name)));
    ASSERT_TRUE(alpha.ok()) << alpha.status().message();
    EXPECT_EQ(alpha->channels, 1);
  }
  const Result<Json> truth = ReadJsonFile(dir / kPhotoTruthFile);
  ASSERT_TRUE(truth.ok()) << truth.status().message();
  EXPECT_EQ((*truth)["options"]["num_photos"], 3);
  ASSERT_EQ((*truth)["photos"].size(), 3u);
  const Json& p1 = (*truth)["photos"][1];
  EXPECT_EQ(p1["file"], "photos/photo_001.png");
  EXPECT_EQ(p1["alpha_file"], "truth/alpha_001.png");
  EXPECT_EQ(p1["landmarks_2d"].size(), 68u);
  EXPECT_EQ(p1["expression"].size(), size_t(face::kNumExpressions));
  const Mat4d& m = SmallPhotos()[1].camera.world_from_cam();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) EXPECT_EQ(p1["camera_to_head"][r][c].get<double>(), m(r, c));
  EXPECT_DOUBLE_EQ(p1["fl_x"].get<double>(), SmallPhotos()[1].camera.intrinsics().fl_x);
  // The identity's true shape scales, by name.
  const auto scales = IdentityParams::FromSeed(o.identity_seed).shape.ToArray();
  ASSERT_EQ((*truth)["shape"].size(), size_t(face::ShapeParams::kCount));
  for (int i = 0; i < face::ShapeParams::kCount; ++i)
    EXPECT_NEAR((*truth)["shape"][face::kShapeParamNames[i]].get<double>(), scales[i], 1e-6)
        << face::kShapeParamNames[i];
  const Result<Json> style = ReadJsonFile(dir / kStyleInfoFile);
  ASSERT_TRUE(style.ok()) << style.status().message();
  EXPECT_EQ((*style)["identity_seed"], 3);
  // Rewriting is byte-identical.
  const Result<std::string> before = ReadFile(dir / kPhotoTruthFile);
  ASSERT_TRUE(WritePhotoSet(o, SmallPhotos(), dir).ok());
  EXPECT_EQ(*before, *ReadFile(dir / kPhotoTruthFile));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace icef::synth
