#include "icef/app/export_app.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

#include "icef/core/parallel.h"
#include "icef/core/progress.h"
#include "icef/face/ict_model.h"
#include "icef/mesh/glb.h"
#include "icef/model/ict_prior.h"
#include "icef/model/render_image.h"
#include "icef/model/trained_model.h"

namespace icef {

namespace {

constexpr int64_t kBatch = 1 << 16;    // field queries per call
constexpr int kSolveIterations = 24;   // most fixed-point steps of the morph-target solve
constexpr int kColorSamples = 16;      // samples of a vertex's colour ray
constexpr float kColorReach = 6.f;     // the colour ray runs this many grid cells either side
constexpr int kLevelSamples = 48;      // samples per pixel ray that SurfaceLevel reads the density on
constexpr float kLevelWindow = 0.25f;  // their span either side of the expected depth (world units)
constexpr int kLevelCandidates = 32;   // levels SurfaceLevel chooses among (geometric, over its densities)

std::string FormatNumber(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

float SrgbToLinear(float c) {
  c = std::clamp(c, 0.f, 1.f);
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// The static density on a grid over the model's box, `resolution` points along its longest side.
mesh::ScalarGrid DensityGrid(const AvatarModel& model, int resolution, const Executor& executor,
                             bool progress, std::ostream& out) {
  const Aabb& box = model.setup().aabb;
  mesh::ScalarGrid grid;
  grid.cell = box.Extent().maxCoeff() / static_cast<float>(resolution - 1);
  grid.origin = box.min;
  for (int a = 0; a < 3; ++a)
    grid.dims[a] = std::max(2, static_cast<int>(std::ceil(box.Extent()[a] / grid.cell)) + 1);
  const int64_t n = int64_t{grid.dims[0]} * grid.dims[1] * grid.dims[2];
  grid.values.resize(n);
  ProgressBar bar("density grid", n, out, progress);
  std::vector<float> points, dirs, rgb;
  for (int64_t begin = 0; begin < n; begin += kBatch) {
    const int64_t m = std::min(kBatch, n - begin);
    points.resize(3 * m), dirs.assign(3 * m, 0.f), rgb.resize(3 * m);
    for (int64_t q = 0; q < m; ++q) {
      const int64_t g = begin + q;
      const int i = static_cast<int>(g % grid.dims[0]), j = static_cast<int>(g / grid.dims[0] % grid.dims[1]),
                k = static_cast<int>(g / (int64_t{grid.dims[0]} * grid.dims[1]));
      Eigen::Map<Vec3f>(points.data() + 3 * q) = grid.point(i, j, k);
      dirs[3 * q + 2] = -1.f;
    }
    model.QueryStatic(executor, m, points.data(), dirs.data(), nullptr, grid.values.data() + begin,
                      rgb.data());
    bar.Update(begin + m);
  }
  if (progress) bar.Finish();
  return grid;
}

// The direction each vertex is seen along in colour: from the training camera that faces it most (the
// directions the view-dependent colour was trained on), else along -normal.
std::vector<Vec3f> ViewDirections(const ModelSetup& setup, const mesh::TriangleMesh& mesh,
                                  const std::vector<Vec3f>& normals) {
  std::vector<Vec3f> view(mesh.positions.size());
  for (size_t v = 0; v < view.size(); ++v) {
    view[v] = normals[v] == Vec3f::Zero() ? Vec3f(0, 0, -1) : Vec3f(-normals[v]);
    float best = 0.f;
    for (const Camera& c : setup.training_cameras) {
      const Vec3f to_camera = (c.Center().cast<float>() - mesh.positions[v]).normalized();
      const float facing = to_camera.dot(normals[v]);
      if (facing > best) best = facing, view[v] = -to_camera;
    }
  }
  return view;
}

// Each vertex's colour: samples on a ray through it along its ViewDirections line of sight, their
// colours queried in that direction, composited front to back.
std::vector<Vec3f> BakeColors(const AvatarModel& model, const mesh::TriangleMesh& mesh,
                              const std::vector<Vec3f>& normals, float cell, const Executor& executor) {
  const int64_t n = static_cast<int64_t>(mesh.positions.size());
  const float step = 2.f * kColorReach * cell / kColorSamples;
  const std::vector<Vec3f> view = ViewDirections(model.setup(), mesh, normals);
  std::vector<float> points(3 * n * kColorSamples), dirs(3 * n * kColorSamples), sigma(n * kColorSamples),
      rgb(3 * n * kColorSamples);
  for (int64_t v = 0; v < n; ++v) {
    for (int s = 0; s < kColorSamples; ++s) {
      const int64_t q = v * kColorSamples + s;
      const float t = -kColorReach * cell + (static_cast<float>(s) + 0.5f) * step;
      Eigen::Map<Vec3f>(points.data() + 3 * q) = mesh.positions[v] + t * view[v];
      Eigen::Map<Vec3f>(dirs.data() + 3 * q) = view[v];
    }
  }
  model.QueryStatic(executor, n * kColorSamples, points.data(), dirs.data(), nullptr, sigma.data(),
                    rgb.data());
  std::vector<Vec3f> colors(n);
  for (int64_t v = 0; v < n; ++v) {
    Vec3f sum = Vec3f::Zero();
    float transmittance = 1.f, weight = 0.f;
    for (int s = 0; s < kColorSamples; ++s) {
      const int64_t q = v * kColorSamples + s;
      const float alpha = 1.f - std::exp(-std::max(sigma[q], 0.f) * step);
      sum += transmittance * alpha * Eigen::Map<const Vec3f>(rgb.data() + 3 * q);
      weight += transmittance * alpha;
      transmittance *= 1.f - alpha;
    }
    const Vec3f c = weight > 1e-6f ? Vec3f(sum / weight)
                                   : Vec3f(Eigen::Map<const Vec3f>(rgb.data() + 3 * v * kColorSamples));
    colors[v] = Vec3f(SrgbToLinear(c.x()), SrgbToLinear(c.y()), SrgbToLinear(c.z()));
  }
  return colors;
}

// One ray's densities [samples] (dt apart): for each level, how far (in samples) the point where the
// density first reaches it lies from the median of where the ray ends in the window (where half the window's
// opacity has accumulated; for an opaque surface, where the transmittance falls through one half).
void AddLevelGaps(const float* d, int samples, float dt, const std::vector<float>& levels,
                  std::vector<std::vector<float>>* gaps) {
  float total = 0.f;
  for (int s = 0; s < samples; ++s) total += std::max(d[s], 0.f) * dt;
  if (!(total > 0.f)) return;
  const float target = -std::log(0.5f * (1.f + std::exp(-total)));  // the optical depth of half the opacity
  float optical = 0.f, half = -1.f;
  for (int s = 0; s < samples && half < 0; ++s) {
    const float step = std::max(d[s], 0.f) * dt;
    if (optical + step >= target) half = s + (target - optical) / step;
    optical += step;
  }
  if (half < 0) return;
  for (size_t c = 0; c < levels.size(); ++c) {
    int s = 0;
    while (s < samples && d[s] < levels[c]) ++s;
    float at = static_cast<float>(s);  // the crossing between sample centres, linear in the density
    if (s > 0 && s < samples) at = s - 1 + (levels[c] - d[s - 1]) / (d[s] - d[s - 1]);
    (*gaps)[c].push_back(std::abs(at + 0.5f - half));
  }
}

// The density at which the renders put the surface: each training camera (at 64 pixels high) renders
// its training expression; every pixel with opacity above one half gets a ray of samples around its
// expected depth, warped to canonical space; the level is the one (of kLevelCandidates spaced
// geometrically between the 5th and 99th percentiles of the positive densities seen) whose crossing lies,
// on average, nearest the point where the ray's transmittance falls through one half (the median
// of where the render's ray ends; AddLevelGaps).
Result<double> SurfaceLevel(const AvatarModel& model, const Executor& executor) {
  const ModelSetup& setup = model.setup();
  std::vector<float> densities;  // [rays][kLevelSamples]
  for (size_t k = 0; k < setup.training_cameras.size() && k < setup.training_expressions.size(); ++k) {
    const Camera& full = setup.training_cameras[k];
    Intrinsics in = full.intrinsics();
    const double scale = std::min(1.0, 64.0 / in.height);
    in.width = std::max(1, static_cast<int>(std::lround(in.width * scale)));
    in.height = std::max(1, static_cast<int>(std::lround(in.height * scale)));
    in.fl_x *= scale, in.fl_y *= scale, in.cx *= scale, in.cy *= scale;
    const Camera camera(in, full.world_from_cam());
    const std::vector<float>& beta = setup.training_expressions[k];
    const RenderedImage image = RenderImage(model, camera, beta, Vec3f::Zero(), executor);
    // Each opaque pixel's ray, kLevelSamples samples across kLevelWindow either side of its expected
    // depth, warped into canonical space.
    std::vector<float> points, offsets, dirs, sigma, rgb;
    for (int j = 0; j < in.height; ++j)
      for (int i = 0; i < in.width; ++i) {
        if (!(image.opacity.At(i, j, 0) > 0.5f) || !(image.depth.At(i, j, 0) > 0.f)) continue;
        const Ray ray = camera.PixelRay(i, j);
        for (int s = 0; s < kLevelSamples; ++s) {
          const float t = image.depth.At(i, j, 0) + kLevelWindow * (2.f * (s + 0.5f) / kLevelSamples - 1.f);
          const Vec3f x = ray.At(t);
          points.insert(points.end(), {x.x(), x.y(), x.z()});
          dirs.insert(dirs.end(), {ray.direction.x(), ray.direction.y(), ray.direction.z()});
        }
      }
    const int64_t n = static_cast<int64_t>(points.size() / 3);
    if (n == 0) continue;
    offsets.resize(points.size()), sigma.resize(n), rgb.resize(3 * n);
    model.Offsets(executor, n, points.data(), beta, offsets.data());
    for (size_t q = 0; q < points.size(); ++q) points[q] += offsets[q];
    model.QueryStatic(executor, n, points.data(), dirs.data(), nullptr, sigma.data(), rgb.data());
    densities.insert(densities.end(), sigma.begin(), sigma.end());
  }
  Result<double> level = HalfOpacityLevel(densities, kLevelSamples, 2.f * kLevelWindow / kLevelSamples);
  if (!level.ok())
    return Status::Error(
        "no training view of the model renders an opaque pixel to find the surface density at; "
        "give --density");
  return level;
}

struct TargetSpec {
  std::string name;
  std::vector<float> beta;
};

// One target per expression of the model's space: ARKit names for ICT-FaceKit's, the setup's else.
Result<std::vector<TargetSpec>> TargetSpecs(const ModelSetup& setup) {
  std::vector<TargetSpec> specs;
  const int dims = setup.expression_dim;
  ICEF_ASSIGN_OR_RETURN(std::shared_ptr<const face::IctModel> ict, face::IctModel::LoadDefault());
  if (IsIctExpressionSpace(*ict, setup.expression_names)) {
    for (const std::string& name : ict->ArkitNames()) {
      TargetSpec spec{name, std::vector<float>(dims, 0.f)};
      for (int e : ict->ExpressionTargets(name)) spec.beta[e] = 1.f;
      specs.push_back(std::move(spec));
    }
    return specs;
  }
  for (int e = 0; e < dims; ++e) {
    TargetSpec spec{e < static_cast<int>(setup.expression_names.size()) ? setup.expression_names[e]
                                                                        : "expression_" + std::to_string(e),
                    std::vector<float>(dims, 0.f)};
    spec.beta[e] = 1.f;
    specs.push_back(std::move(spec));
  }
  return specs;
}

// The displacement x - v of every vertex v, x solving x + D(x, beta) = v by fixed-point steps
// x <- v - D(x), each vertex until its step is below `tolerance` (most take two or three: far from
// the face D is nearly constant). Where the warp folds (its fade, the lips' medial axis) there may be
// no solution: the last iterate stays, and *unsolved counts those left above `tolerance`.
std::vector<Vec3f> SolveTarget(const AvatarModel& model, const std::vector<Vec3f>& base,
                               const std::vector<float>& beta, float tolerance, const Executor& executor,
                               int64_t* unsolved) {
  std::vector<Vec3f> x = base;
  std::vector<int64_t> active(base.size());
  std::iota(active.begin(), active.end(), int64_t{0});
  std::vector<Vec3f> points, offsets;
  for (int it = 0; it < kSolveIterations && !active.empty(); ++it) {
    points.resize(active.size()), offsets.resize(active.size());
    for (size_t a = 0; a < active.size(); ++a) points[a] = x[active[a]];
    model.Offsets(executor, static_cast<int64_t>(active.size()), points.data()->data(), beta,
                  offsets.data()->data());
    std::vector<int64_t> next;
    for (size_t a = 0; a < active.size(); ++a) {
      const int64_t v = active[a];
      const Vec3f step = base[v] - offsets[a] - x[v];  // = -(x + D(x) - v), the residual
      x[v] += step;
      if (step.norm() >= tolerance) next.push_back(v);
    }
    active = std::move(next);
  }
  *unsolved += static_cast<int64_t>(active.size());
  std::vector<Vec3f> displacement(base.size());
  for (size_t v = 0; v < base.size(); ++v) displacement[v] = x[v] - base[v];
  return displacement;
}

// Zeroes displacements below `floor` (the learned residual's faint motion far from the face), so a
// target stores only the vertices it visibly moves.
void DropFaint(std::vector<Vec3f>* displacements, float floor) {
  for (Vec3f& d : *displacements)
    if (d.norm() < floor) d = Vec3f::Zero();
}

Result<mesh::TriangleMesh> ExtractSurface(const AvatarModel& model, const ExportAppOptions& o, double level,
                                          const Executor& executor, float* cell, std::ostream& out) {
  const mesh::ScalarGrid grid = DensityGrid(model, o.resolution, executor, o.progress, out);
  *cell = grid.cell;
  mesh::TriangleMesh surface = mesh::SurfaceNets(grid, static_cast<float>(level));
  if (surface.triangles.empty())
    return Status::Error(o.model.string() + ": the canonical density never exceeds " + FormatNumber(level) +
                         " inside the model's box (its largest is " +
                         FormatNumber(*std::max_element(grid.values.begin(), grid.values.end())) +
                         "; give a lower --density)");
  surface = mesh::KeepLargePieces(surface, 0.02);
  return mesh::Simplify(surface, static_cast<size_t>(o.max_triangles));
}

}  // namespace

Status ExportAppOptions::Validate() const {
  if (out.extension() != ".glb") return Status::Error("--out: " + out.string() + " is not a .glb file name");
  if (resolution < 16 || resolution > 1024) return Status::Error("--resolution: between 16 and 1024");
  if (max_triangles < 100) return Status::Error("--triangles: at least 100");
  if (density && (!(*density > 0) || !std::isfinite(*density)))
    return Status::Error("--density: a positive number");
  return Status::Ok();
}

Result<double> HalfOpacityLevel(std::span<const float> densities, int samples_per_ray, float dt) {
  std::vector<float> positive;
  for (float d : densities)
    if (d > 0.f) positive.push_back(d);
  if (positive.empty()) return Status::Error("no ray sees any density");
  std::sort(positive.begin(), positive.end());
  const float lo = positive[positive.size() / 20], hi = positive[positive.size() * 99 / 100];
  std::vector<float> levels(kLevelCandidates);
  for (int c = 0; c < kLevelCandidates; ++c) levels[c] = lo * std::pow(hi / lo, c / (kLevelCandidates - 1.f));
  std::vector<std::vector<float>> gaps(levels.size());  // per level: |crossing - half point|, samples
  for (size_t r = 0; r < densities.size() / samples_per_ray; ++r)
    AddLevelGaps(densities.data() + r * samples_per_ray, samples_per_ray, dt, levels, &gaps);
  // The level whose crossings lie nearest the half points (mean over the rays).
  size_t best = 0;
  double best_gap = std::numeric_limits<double>::max();
  for (size_t c = 0; c < levels.size(); ++c) {
    if (gaps[c].empty()) continue;
    const double gap = std::accumulate(gaps[c].begin(), gaps[c].end(), 0.0) / gaps[c].size();
    if (gap < best_gap) best_gap = gap, best = c;
  }
  return static_cast<double>(levels[best]);
}

Result<ExportSummary> RunExport(const ExportAppOptions& o, std::ostream& out) {
  ICEF_RETURN_IF_ERROR(o.Validate());
  ICEF_ASSIGN_OR_RETURN(const TrainedModel loaded, LoadTrainedModel(o.model, Executor(o.threads)));
  return ExportLoadedModel(loaded, o, out);
}

Result<ExportSummary> ExportLoadedModel(const TrainedModel& loaded, const ExportAppOptions& o,
                                        std::ostream& out) {
  const Executor executor(o.threads);
  const AvatarModel& model = *loaded.model;
  if (model.traits().entangled_beta)
    return Status::Error(o.model.string() +
                         ": a nerface model has no canonical head to export (its density "
                         "depends on the expression); export a model of another method");
  ExportSummary summary;
  if (o.density) {
    summary.density = *o.density;
  } else {
    Result<double> level = SurfaceLevel(model, executor);
    if (!level.ok()) return level.status().WithContext(o.model.string());
    summary.density = *level;
  }
  float cell = 0;
  ICEF_ASSIGN_OR_RETURN(const mesh::TriangleMesh surface,
                        ExtractSurface(model, o, summary.density, executor, &cell, out));
  mesh::GlbMesh glb;
  glb.mesh = surface;
  glb.normals = mesh::VertexNormals(surface);
  glb.colors = BakeColors(model, surface, glb.normals, cell, executor);
  if (model.traits().prior && model.warp() != nullptr) {
    ICEF_ASSIGN_OR_RETURN(const std::vector<TargetSpec> specs, TargetSpecs(model.setup()));
    ProgressBar bar("morph targets", static_cast<int64_t>(specs.size()), out, o.progress);
    for (const TargetSpec& spec : specs) {
      bar.Update(static_cast<int64_t>(summary.targets.size()), spec.name);
      std::vector<Vec3f> d =
          SolveTarget(model, surface.positions, spec.beta, 1e-3f * cell, executor, &summary.unsolved);
      DropFaint(&d, 0.05f * cell);
      glb.targets.push_back({spec.name, std::move(d)});
      summary.targets.push_back(spec.name);
    }
    if (o.progress) bar.Finish();
  } else {
    summary.note =
        "method " + loaded.config.method +
        " has no face-model prior, so the mesh is static (no morph targets); train with icef-prior "
        "for expressions";
  }
  glb.extras = {{"generator", "icef export"},
                {"source", o.model.string()},
                {"method", loaded.config.method},
                {"training_steps", loaded.step},
                {"density_level", summary.density}};
  if (model.setup().ict_fit)
    glb.extras["licence"] =
        "Morph targets derived from ICT-FaceKit (USC Institute for Creative Technologies), MIT licence";
  ICEF_RETURN_IF_ERROR(mesh::WriteGlb(glb, o.out));
  summary.vertices = static_cast<int64_t>(surface.positions.size());
  summary.triangles = static_cast<int64_t>(surface.triangles.size());
  return summary;
}

}  // namespace icef
