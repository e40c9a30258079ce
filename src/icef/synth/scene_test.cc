// The scene axes of `icef synth --diverse` (synthesize.h SceneAxes, ResolveScene, identity.h
// DrawDiverseSkin / DrawFineDetail): the classic scene is untouched when no axis is drawn, six
// consecutive seeds span every axis, pinning an axis leaves the others' draws alone, a placed head
// keeps its cameras, 3D landmarks and 2D landmarks consistent, and every drawn scene is lit.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "icef/data/dataset.h"
#include "icef/synth/ground_truth_renderer.h"
#include "icef/synth/head_model.h"
#include "icef/synth/synthesize.h"

namespace icef::synth {
namespace {

namespace fs = std::filesystem;

constexpr uint64_t kFirstSeed = 101;  // six consecutive seeds, as the validation bench uses

float Luma(const Vec3f& c) { return c.dot(Vec3f(0.2126f, 0.7152f, 0.0722f)); }

SynthOptions Diverse(uint64_t seed) {
  SynthOptions o;
  o.out_dir = "unused";
  o.identity_seed = seed;
  o.vary = SceneAxes::All();
  return o;
}

TEST(SceneTest, NoAxisKeepsTheClassicScene) {
  SynthOptions o;
  o.out_dir = "unused";
  o.identity_seed = 7;
  EXPECT_EQ(ResolveScene(o).ToString(), o.ToString());
  EXPECT_EQ(SynthIdentity(o).ToString(), IdentityParams::FromSeed(7).ToString());
  EXPECT_FALSE(o.vary.Any());
  EXPECT_EQ(o.vary.ToString(), "none");
}

TEST(SceneTest, AxesParseByNameAndRejectUnknownOnes) {
  SceneAxes a;
  ASSERT_TRUE(a.Set("lighting", true).ok());
  ASSERT_TRUE(a.Set("detail", true).ok());
  EXPECT_EQ(a.ToString(), "lighting,detail");
  const Status bad = a.Set("weather", true);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("weather"), std::string::npos);
  EXPECT_NE(bad.message().find("placement"), std::string::npos);  // lists the known axes
  EXPECT_EQ(SceneAxes::All().ToString(), "skin,lighting,placement,camera,views,resolution,detail");
}

TEST(SceneTest, SixConsecutiveSeedsSpanEveryAxis) {
  float luma_min = 1, luma_max = 0;
  double scale_min = 9, scale_max = 0, yaw_min = 90, yaw_max = 0, size_min = 9, size_max = 0, az_min = 9,
         az_max = -9;
  int second_lights = 0;
  for (uint64_t seed = kFirstSeed; seed < kFirstSeed + 6; ++seed) {
    const SynthOptions o = ResolveScene(Diverse(seed));
    ASSERT_TRUE(o.Validate().ok()) << seed << ": " << o.Validate().message();
    const IdentityParams id = SynthIdentity(o);
    luma_min = std::min(luma_min, Luma(id.skin_tone)), luma_max = std::max(luma_max, Luma(id.skin_tone));
    // Brows keep their contrast against any skin.
    EXPECT_LT(Luma(id.brow_color) * 2.4f, Luma(id.skin_tone)) << seed;
    EXPECT_LT(Luma(id.lip_color), Luma(id.skin_tone)) << seed;
    scale_min = std::min(scale_min, o.head_scale), scale_max = std::max(scale_max, o.head_scale);
    yaw_min = std::min(yaw_min, o.max_yaw_deg), yaw_max = std::max(yaw_max, o.max_yaw_deg);
    const double size = o.focal_scale / o.camera_distance;  // head size in the image, up to a constant
    size_min = std::min(size_min, size), size_max = std::max(size_max, size);
    const double az = std::atan2(o.render.light_direction.x(), o.render.light_direction.z());
    az_min = std::min(az_min, az), az_max = std::max(az_max, az);
    second_lights += o.render.fill > 0.f;
    EXPECT_GT(id.pore_scale, 1.f) << seed;
    EXPECT_GT(id.wrinkle_strength, 0.f) << seed;
    EXPECT_GE(o.resolution, 128);
    EXPECT_LE(o.resolution, 512);
  }
  EXPECT_LT(luma_min, 0.22f);  // very dark skin
  EXPECT_GT(luma_max, 0.72f);  // very light skin
  EXPECT_GT(scale_max - scale_min, 0.3);
  EXPECT_GT(yaw_max - yaw_min, 20.0);
  EXPECT_GT(size_max / size_min, 1.4);
  EXPECT_GT(az_max - az_min, 1.5);  // radians: key lights from both sides
  EXPECT_GT(second_lights, 0);
  EXPECT_LT(second_lights, 6);
}

TEST(SceneTest, PinningOneAxisLeavesTheOthersDrawsAlone) {
  const SynthOptions all = ResolveScene(Diverse(103));
  SynthOptions pinned_in = Diverse(103);
  ASSERT_TRUE(pinned_in.vary.Set("lighting", false).ok());
  const SynthOptions pinned = ResolveScene(pinned_in);
  const SynthOptions classic;
  EXPECT_EQ(pinned.render.ToString(), classic.render.ToString());  // lighting pinned: classic
  EXPECT_EQ(pinned.head_scale, all.head_scale);
  EXPECT_EQ(pinned.head_offset, all.head_offset);
  EXPECT_EQ(pinned.camera_distance, all.camera_distance);
  EXPECT_EQ(pinned.max_yaw_deg, all.max_yaw_deg);
  EXPECT_EQ(pinned.resolution, all.resolution);
  EXPECT_EQ(SynthIdentity(pinned).ToString(), SynthIdentity(all).ToString());
}

TEST(SceneTest, ValidateKeepsTheHeadInsideTheBox) {
  SynthOptions o;
  o.out_dir = "unused";
  o.head_scale = 1.0;
  o.head_offset = Vec3d(0.0, 0.0, 0.7);  // the face would poke out of z = 1
  const Status s = o.Validate();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("head_offset"), std::string::npos);
  o.head_offset = Vec3d(0.0, 0.0, 0.3);
  EXPECT_TRUE(o.Validate().ok()) << o.Validate().message();
  for (uint64_t seed = 1; seed < 40; ++seed) EXPECT_TRUE(ResolveScene(Diverse(seed)).Validate().ok()) << seed;
}

// The dataset's world frame is the head frame scaled and shifted: the cameras and 3D landmarks are
// written in it, and projecting a frame's 3D landmarks through its camera gives its 2D landmarks.
TEST(SceneTest, PlacedHeadKeepsCamerasAndLandmarksConsistent) {
  const fs::path dir = fs::temp_directory_path() / ("icef_scene_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  SynthOptions o;
  o.out_dir = dir;
  o.identity_seed = 104;
  o.num_train = 2;
  o.resolution = 24;
  o.test_views = 1;
  o.novel_per_tier = 0;
  o.render.supersample = 1;
  o.vary.placement = o.vary.camera = o.vary.views = true;
  const SynthOptions resolved = ResolveScene(o);
  ASSERT_GT(std::abs(resolved.head_scale - 1.0), 0.05);
  ASSERT_GT(resolved.head_offset.norm(), 0.1);
  Dataset written;
  ASSERT_TRUE(SynthesizeDataset(o, Executor(1), nullptr, &written).ok());
  ASSERT_TRUE(fs::exists(dir / kSceneInfoFile));
  int checked = 0;
  for (const auto* split : {&written.train, &written.test}) {
    for (const Frame& f : *split) {
      ASSERT_TRUE(f.landmarks_3d && f.landmarks_2d);
      for (size_t i = 0; i < f.landmarks_3d->size(); ++i) {
        const Vec3d p = (*f.landmarks_3d)[i].cast<double>();
        EXPECT_LE(p.cwiseAbs().maxCoeff(), 1.0);
        const auto proj = f.camera.Project(p);
        ASSERT_TRUE(proj.has_value());
        EXPECT_NEAR(proj->uv.x(), (*f.landmarks_2d)[i].x(), 2e-3) << f.file_path << " landmark " << i;
        EXPECT_NEAR(proj->uv.y(), (*f.landmarks_2d)[i].y(), 2e-3) << f.file_path << " landmark " << i;
        ++checked;
      }
      EXPECT_GT(f.camera.Center().cwiseAbs().maxCoeff(), 1.0);  // outside the box
      EXPECT_NEAR(f.camera.Center().norm() / resolved.camera_distance, resolved.head_scale, 0.6);
    }
  }
  EXPECT_GT(checked, 68 * 3);
  fs::remove_all(dir);
}

// Every drawn scene of six seeds lights the face: the covered pixels of a frontal render are
// neither black nor blown out; a specular sheen brightens the face.
TEST(SceneTest, DrawnScenesAreLitAndTheSheenShows) {
  for (uint64_t seed = kFirstSeed; seed < kFirstSeed + 6; ++seed) {
    SynthOptions o = ResolveScene(Diverse(seed));
    o.render.supersample = 1;
    const HeadModel head(SynthIdentity(o));
    Intrinsics in;
    in.width = in.height = 40;
    in.fl_x = in.fl_y = 3.6 * 40;
    in.cx = in.cy = 20;
    const Image image =
        RenderGroundTruth(head, OrbitCamera(in, 3.5, 0, 0), std::vector<float>(face::kNumExpressions, 0.f),
                          Executor(1), o.render);
    double sum = 0;
    int n = 0, clipped = 0;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        if (image.At(x, y, 3) > 0.99f) {
          const float l = Luma(image.Rgb(x, y));
          sum += l, ++n, clipped += l > 0.995f;
        }
    ASSERT_GT(n, 100) << seed;
    EXPECT_GT(sum / n, 0.06) << seed << ": " << o.render.ToString();
    EXPECT_LT(sum / n, 0.9) << seed;
    EXPECT_LT(clipped, n / 20) << seed;
  }
  RenderOptions shiny;
  shiny.specular = 0.3f;
  shiny.supersample = 1;
  const HeadModel head(IdentityParams::Average());
  Intrinsics in;
  in.width = in.height = 32;
  in.fl_x = in.fl_y = 3.6 * 32;
  in.cx = in.cy = 16;
  const std::vector<float> neutral(face::kNumExpressions, 0.f);
  const Camera front = OrbitCamera(in, 3.5, 0, 0);
  const Image matte = RenderGroundTruth(head, front, neutral, Executor(1), RenderOptions{.supersample = 1});
  const Image sheen = RenderGroundTruth(head, front, neutral, Executor(1), shiny);
  double added = 0;
  for (size_t i = 0; i < matte.pixels.size(); ++i) added += sheen.pixels[i] - matte.pixels[i];
  EXPECT_GT(added, 1.0);  // the sheen brightens the face
}

}  // namespace
}  // namespace icef::synth
