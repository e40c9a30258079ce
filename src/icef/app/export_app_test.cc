#include "icef/app/export_app.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "icef/app/app_test_util.h"
#include "icef/face/ict_model.h"
#include "icef/mesh/glb.h"
#include "icef/model/trained_model.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

// The median static density of the model over its box: a level its surface exists at (the tiny
// models are untrained).
double MedianDensity(const fs::path& model_dir) {
  const Executor executor(1);
  const TrainedModel loaded = std::move(LoadTrainedModel(model_dir, executor)).value();
  const Aabb& box = loaded.model->setup().aabb;
  std::vector<float> points, dirs, sigma(4096), rgb(3 * 4096);
  for (int q = 0; q < 4096; ++q) {
    const Vec3f u((q % 16 + 0.5f) / 16.f, (q / 16 % 16 + 0.5f) / 16.f, (q / 256 + 0.5f) / 16.f);
    const Vec3f p = box.min + u.cwiseProduct(box.Extent());
    points.insert(points.end(), {p.x(), p.y(), p.z()});
    dirs.insert(dirs.end(), {0.f, 0.f, -1.f});
  }
  loaded.model->QueryStatic(executor, 4096, points.data(), dirs.data(), nullptr, sigma.data(), rgb.data());
  std::nth_element(sigma.begin(), sigma.begin() + 2048, sigma.end());
  return sigma[2048];
}

// A model in ICT-FaceKit's expression space on its prior: the tiny box is 40 cm of the ICT head.
ModelSetup IctSetup(const face::IctModel& ict) {
  ModelSetup setup = testing_model::TinySetup(ict.num_expressions());
  setup.expression_names = ict.expression_names();
  IctFaceFit fit;
  fit.head_from_world.scale = 40.0;
  setup.ict_fit = fit;
  return setup;
}

TEST(ExportApp, IctModelGetsArkitNamedMorphTargetsTheWarpSolves) {
  const fs::path dir = testing::MakeTempDir("export_app_ict");
  const std::shared_ptr<const face::IctModel> ict = *face::IctModel::LoadDefault();
  ExportAppOptions o;
  o.model = testing_app::WriteTinyModelDir(dir / "model", IctSetup(*ict), "icef-prior", 0.5f);
  o.out = dir / "avatar.glb";
  o.resolution = 24;
  o.max_triangles = 3000;
  o.density = MedianDensity(o.model);
  o.threads = 2;
  std::ostringstream out;
  const Result<ExportSummary> s = RunExport(o, out);
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_TRUE(s->note.empty());
  EXPECT_LE(s->triangles, 3000);
  const Result<mesh::GlbSummary> glb = mesh::ReadGlbSummary(o.out);
  ASSERT_TRUE(glb.ok()) << glb.status().message();
  EXPECT_EQ(glb->target_names, ict->ArkitNames());
  EXPECT_EQ(glb->vertices, static_cast<size_t>(s->vertices));
  EXPECT_NE(glb->asset_extras.value("licence", "").find("ICT-FaceKit"), std::string::npos);
  // jawOpen moves the vertices near the chin; each moved vertex x = v + d is taken back to v by the
  // model's warp at jawOpen = 1.
  const auto jaw = std::find(glb->target_names.begin(), glb->target_names.end(), "jawOpen");
  const int target = static_cast<int>(jaw - glb->target_names.begin());
  EXPECT_GT(glb->target_moved[target], 10u);
  const std::vector<Vec3f> d = *mesh::ReadGlbTarget(o.out, target);
  const Executor executor(1);
  const TrainedModel loaded = std::move(LoadTrainedModel(o.model, executor)).value();
  std::vector<float> beta(ict->num_expressions(), 0.f);
  beta[ict->ExpressionIndex("jawOpen")] = 1.f;
  int checked = 0, solved = 0;
  const std::vector<Vec3f> base = *mesh::ReadGlbPositions(o.out);
  std::vector<Vec3f> x(base.size()), offsets(base.size());
  for (size_t v = 0; v < base.size(); ++v) x[v] = base[v] + d[v];
  loaded.model->Offsets(executor, static_cast<int64_t>(x.size()), x.data()->data(), beta,
                        offsets.data()->data());
  for (size_t v = 0; v < base.size(); ++v) {
    if (d[v] == Vec3f::Zero()) continue;
    ++checked;
    solved += (x[v] + offsets[v] - base[v]).norm() < 1e-4f;
  }
  EXPECT_GT(checked, 10);
  EXPECT_GE(solved, checked - s->unsolved)
      << solved << " of " << checked << ", " << s->unsolved << " unsolved";
}

TEST(ExportApp, ModelsWithoutAPriorExportAStaticMeshAndNerfaceIsRefused) {
  const fs::path dir = testing::MakeTempDir("export_app_static");
  ExportAppOptions o;
  o.model = testing_app::WriteTinyModelDir(dir / "model", testing_model::TinySetup(), "icef", 0.5f);
  o.out = dir / "static.glb";
  o.resolution = 20;
  o.density = MedianDensity(o.model);
  o.threads = 1;
  std::ostringstream out;
  const Result<ExportSummary> s = RunExport(o, out);
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_TRUE(s->targets.empty());
  EXPECT_NE(s->note.find("no face-model prior"), std::string::npos) << s->note;
  EXPECT_TRUE(mesh::ReadGlbSummary(o.out)->target_names.empty());

  o.model = testing_app::WriteTinyModelDir(dir / "nerface", testing_model::TinySetup(), "nerface");
  o.out = dir / "nerface.glb";
  EXPECT_NE(RunExport(o, out).status().message().find("no canonical head"), std::string::npos);
  EXPECT_FALSE(fs::exists(o.out));
  o.out = dir / "avatar.gltf";
  EXPECT_NE(RunExport(o, out).status().message().find("--out"), std::string::npos);
  o.out = dir / "high.glb";
  o.model = dir / "model";
  o.density = 1e30;
  EXPECT_NE(RunExport(o, out).status().message().find(
                "never exceeds 1e+30 inside the model's box (its largest is "),
            std::string::npos);
  EXPECT_FALSE(fs::exists(o.out));
}

// Rays through a density ramp d = a (s - s0) (s0 varying per ray): opacity accumulates as
// a dt (s - s0)^2 / 2, so half of it is reached at s - s0 = sqrt(2 ln 2 / (a dt)), where the density is
// sqrt(2 ln 2 a / dt): the level chosen, within the candidates' spacing; at any density scale.
TEST(HalfOpacityLevel, IsTheDensityWhereTheRaysReachHalfOpacity) {
  const int samples = 64;
  const float dt = 0.01f, a = 20.f;
  for (float scale : {1.f, 1000.f}) {
    std::vector<float> d;
    for (int r = 0; r < 12; ++r)
      for (int s = 0; s < samples; ++s) d.push_back(scale * a * std::max(0.f, s + 0.5f - (10.f + r)));
    const Result<double> level = HalfOpacityLevel(d, samples, dt / scale);
    ASSERT_TRUE(level.ok()) << level.status().message();
    const double expected = scale * std::sqrt(2 * std::log(2.0) * a / dt);
    EXPECT_NEAR(*level / expected, 1.0, 0.15) << "scale " << scale << ": " << *level << " vs " << expected;
  }
  EXPECT_FALSE(HalfOpacityLevel(std::vector<float>(128, 0.f), samples, dt).ok());
}

}  // namespace
}  // namespace icef
