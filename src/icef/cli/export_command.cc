#include <iostream>
#include <memory>

#include "icef/app/export_app.h"
#include "icef/cli/commands.h"
#include "icef/cli/validators.h"
#include "icef/core/progress.h"

namespace icef::cli {

CommandFn RegisterExport(CLI::App& app) {
  app.description(
      "Export a trained avatar as a glTF 2.0 binary (.glb) for three.js, Blender and game engines: the "
      "canonical head the model learned (surface of its density, hair included, simplified to --triangles), "
      "colours baked from the field into the vertices, and one morph target per expression computed from "
      "the model's warp, named with ARKit's blendshape names (jawOpen, mouthSmileLeft, ...) for models "
      "trained on an icef track --face-model ict dataset. Models without a face-model prior (--method "
      "icef, warp) export a static mesh and say so.");
  auto o = std::make_shared<ExportAppOptions>();
  app.add_option("model", o->model, "Model directory (or checkpoint file)")->required();
  app.add_option("--out", o->out, "The .glb file to write")->required();
  app.add_option("--resolution", o->resolution, "Density grid points along the head box's longest side")
      ->capture_default_str();
  app.add_option("--triangles", o->max_triangles, "Triangle budget of the simplified mesh")
      ->capture_default_str();
  auto density = std::make_shared<double>(0);
  app.add_option(
         "--density", *density,
         "Density of the surface (the level set of the canonical density; default: the density at which "
         "the model's renders of its training views put the surface)")
      ->check(CLI::PositiveNumber);
  app.add_option("--threads", o->threads, "Worker threads (0 = all cores)")->check(kNonNegative);
  return [=]() -> Status {
    ExportAppOptions opts = *o;
    if (*density > 0) opts.density = *density;
    opts.progress = StdoutIsTerminal();
    ICEF_ASSIGN_OR_RETURN(const ExportSummary s, RunExport(opts, std::cout));
    std::cout << "wrote " << opts.out.string() << ": " << s.vertices << " vertices, " << s.triangles
              << " triangles at density " << s.density << ", " << s.targets.size() << " morph targets";
    if (!s.targets.empty())
      std::cout << " (" << s.unsolved << " of " << s.vertices * static_cast<int64_t>(s.targets.size())
                << " vertex-targets where the warp folds and no point maps onto the vertex)";
    std::cout << "\n";
    if (!s.note.empty()) std::cout << "note: " << s.note << "\n";
    return Status::Ok();
  };
}

}  // namespace icef::cli
