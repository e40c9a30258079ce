// The prior shading's light fit (model/prior_light.h) recovers the key light of synthetic heads
// from their training images through the fitted face model.
#include "icef/model/prior_light.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "icef/face/ict_warp.h"
#include "icef/face/mesh_depth.h"
#include "icef/model/face_prior.h"
#include "icef/synth/synthesize.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

// A K = 4 dataset at 64 px lit by `light` (head frame = world frame in the classic scene), its face
// fit and light fit.
Result<PriorLightFit> FitSynthetic(const Vec3f& light, uint64_t seed, const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("icef_prior_light_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  synth::SynthOptions o;
  o.out_dir = dir;
  o.identity_seed = seed;
  o.num_train = 4;
  o.resolution = 64;
  o.test_views = 1;
  o.novel_per_tier = 1;
  o.render.light_direction = light;
  const Executor executor(2);
  ICEF_RETURN_IF_ERROR(synth::SynthesizeDataset(o, executor));
  ICEF_ASSIGN_OR_RETURN(const Dataset dataset, LoadDataset(dir));
  ICEF_ASSIGN_OR_RETURN(const face::FaceFit fit, FitFaceModelToDataset(dataset));
  Result<PriorLightFit> out = FitPriorLight(dataset, fit, executor);
  fs::remove_all(dir);
  return out;
}

// The renderer's light is ambient 0.38 + diffuse 0.72 max(0, n . l): v = (0.72 / 0.38) l.
TEST(PriorLightTest, RecoversTheKeyLightOfSyntheticHeads) {
  const synth::RenderOptions defaults;
  const float strength = defaults.diffuse / defaults.ambient;
  for (const Vec3f& dir : {Vec3f(-0.35f, 0.45f, 0.82f), Vec3f(0.6f, -0.1f, 0.8f)}) {
    const Vec3f want = strength * dir.normalized();
    const Result<PriorLightFit> fit = FitSynthetic(dir, 3, dir.x() < 0 ? "left" : "right");
    ASSERT_TRUE(fit.ok()) << fit.status().message();
    const double angle =
        std::acos(std::clamp(double(fit->light.normalized().dot(want.normalized())), -1.0, 1.0));
    EXPECT_LT(angle * 180 / M_PI, 15.0) << fit->BriefReport();
    EXPECT_GT(fit->light.norm(), 0.7 * strength) << fit->BriefReport();
    EXPECT_LT(fit->light.norm(), 1.4 * strength) << fit->BriefReport();
    EXPECT_GT(fit->pixels, 1000);
    EXPECT_LT(fit->rms, 0.15);  // skin colour varies (cheeks, brows, freckles)
    std::printf("%s\n", fit->BriefReport().c_str());
  }
}

// ICT-FaceKit's fit: views of the posed mesh shaded as the fit models it, rho (1 + max(0, n . v)) on
// the face (its area-weighted vertex normals), written as a dataset; the fit finds v and rho again.
TEST(PriorLightTest, RecoversTheLightThroughTheIctMesh) {
  const face::IctModel& m = **face::IctModel::LoadDefault();
  const face::IctWarp warp = *face::IctWarp::Create(m, {});
  IctFaceFit fit;
  fit.head_from_world.scale = 40;  // 1 world unit = 40 cm
  const Vec3f light(0.4f, 0.6f, 0.9f);
  const Vec3f albedo(0.4f, 0.3f, 0.25f);  // unclipped: at most 0.4 x (1 + |v|) < 1
  const fs::path dir = fs::temp_directory_path() / ("icef_prior_light_ict_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "images");
  Dataset d;
  d.root = dir;
  d.expression_names = m.expression_names();
  d.expression_dim = m.num_expressions();
  const std::vector<Vec3f> normals = warp.VertexNormals(m.neutral());
  std::vector<Vec3f> world;
  for (const Vec3f& p : m.neutral()) world.push_back(p / 40.f);
  for (int k = 0; k < 3; ++k) {
    Intrinsics in;
    in.width = in.height = 96;
    in.fl_x = in.fl_y = 200;
    in.cx = in.cy = 48;
    const double yaw = (k - 1) * 0.5;
    Frame f;
    f.camera = Camera::LookAt(in, Vec3d(std::sin(yaw), 0.05, std::cos(yaw)), Vec3d(0, 0.05, 0.2));
    f.expression.assign(m.num_expressions(), 0.f);
    f.file_path = "images/" + std::to_string(k) + ".png";
    std::vector<int32_t> hit;
    const std::vector<float> depth = face::MeshDepthImage(world, warp.triangles(), f.camera, &hit);
    Image image(96, 96, 4);
    for (int y = 0; y < 96; ++y)
      for (int x = 0; x < 96; ++x) {
        const int32_t t = hit[size_t(y) * 96 + x];
        if (t < 0) continue;
        Vec3f n = Vec3f::Zero();
        for (const uint32_t v : warp.triangles()[t]) n += normals[v];
        const Vec3f c = albedo * (1.f + std::max(0.f, n.normalized().dot(light)));
        for (int ch = 0; ch < 3; ++ch) image.At(x, y, ch) = std::min(c[ch], 1.f);
        image.At(x, y, 3) = 1.f;
      }
    ASSERT_TRUE(WritePng(dir / f.file_path, image).ok());
    d.train.push_back(f);
  }
  const Result<PriorLightFit> out = FitPriorLight(d, fit);
  fs::remove_all(dir);
  ASSERT_TRUE(out.ok()) << out.status().message();
  EXPECT_LT((out->light - light).norm(), 0.1f * light.norm()) << out->BriefReport();
  EXPECT_LT((out->albedo - albedo).norm(), 0.05f) << out->BriefReport();
  EXPECT_GT(out->pixels, 500);
}

}  // namespace
}  // namespace icef
