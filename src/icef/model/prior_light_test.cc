// The prior shading's light fit (model/prior_light.h) recovers the key light of synthetic heads
// from their training images through the fitted face model.
#include "icef/model/prior_light.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

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

}  // namespace
}  // namespace icef
