// `icef export`: a trained avatar as a glTF 2.0 binary (.glb) that engines, Blender and browsers
// load. The mesh is the canonical head the NeRF learned (hair, ears and neck included): surface nets
// over its static density on a grid spanning the model's box (at the density where the renders of its
// training views put the surface, unless given), the small floating pieces dropped, then
// simplified to a triangle budget. Each vertex's colour is what the canonical field shows there
// when looked at from the training camera that faces it most (a short ray through the surface along
// that camera's line of sight, composited as the renderer composites), in linear RGB. Models on a face-model
// prior (icef-prior, warp-prior) get one morph target per expression: each vertex v moved to the observed
// point x that the model's warp takes to v at that expression alone at weight 1 (x + D_final(x, e) = v,
// solved by fixed-point iteration; the learned residual included), named as the expression space names it:
// ARKit's names for models trained in ICT-FaceKit's space (mouthSmileLeft, jawOpen; browInnerUp and cheekPuff
// drive both of ICT's halves), the dataset's names otherwise. Models without a prior export a static mesh and
// say so; `nerface` (no canonical head) is refused.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include "icef/core/status.h"
#include "icef/model/trained_model.h"

namespace icef {

struct ExportAppOptions {
  std::filesystem::path model;    // model directory or checkpoint file
  std::filesystem::path out;      // the .glb to write (atomically)
  int resolution = 192;           // density grid points along the box's longest side
  int64_t max_triangles = 80000;  // simplification budget
  // The level set of the static density (per world unit); by default the level that passes where the
  // rays of the model's renders of its training views end (HalfOpacityLevel).
  std::optional<double> density;
  int threads = 0;        // worker threads (0 = all cores)
  bool progress = false;  // a progress bar on the terminal

  Status Validate() const;
};

struct ExportSummary {
  int64_t vertices = 0, triangles = 0;
  double density = 0;                // the level the surface was taken at
  std::vector<std::string> targets;  // morph target names, in order
  // Vertex-targets whose warp solve did not settle (within 0.001 grid cells; see SolveTarget): where
  // the warp folds, no point maps onto the vertex.
  int64_t unsolved = 0;
  std::string note;  // why there are no morph targets, when there are none
};

Result<ExportSummary> RunExport(const ExportAppOptions& options, std::ostream& out);
// The same for a model already loaded (options.model names it in messages and the GLB's metadata;
// options are not validated here).
Result<ExportSummary> ExportLoadedModel(const TrainedModel& loaded, const ExportAppOptions& options,
                                        std::ostream& out);

// The surface level of a volume seen along rays: densities [rays][samples_per_ray], samples dt apart
// along each ray. Among levels spaced geometrically between the 5th and 99th percentiles of the
// positive densities, the one whose first crossing along each ray lies, on average, nearest the
// median of where the ray ends (where half its opacity has accumulated: for an opaque ray, where the
// transmittance falls through one half). icef export takes the level of its surface from the rays
// of the model's renders of its training views. Error: no positive density.
Result<double> HalfOpacityLevel(std::span<const float> densities, int samples_per_ray, float dt);

}  // namespace icef
