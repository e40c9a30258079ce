// icef synth --out DIR [--identity-seed N --generic-style --k K --res R --test-views V
//   --novel-per-tier N --near T0 --far T1 --diverse --max-res R --vary AXES --pin AXES --threads T
//   --contact-sheet FILE.png]
// icef synth --photos N --out DIR [--identity-seed N --generic-style --res-photo WxH
//   --background-seed S --supersample S --threads T]
// app/synth_app.h.
#include <iostream>
#include <memory>
#include <string>

#include "icef/app/synth_app.h"
#include "icef/cli/commands.h"
#include "icef/core/progress.h"

namespace icef::cli {

CommandFn RegisterSynth(CLI::App& app) {
  auto args = std::make_shared<SynthAppOptions>();
  auto threads = std::make_shared<int>(0);
  auto num_photos = std::make_shared<int>(0);
  synth::SynthOptions& o = args->options;
  app.description(
      "Render a synthetic ground-truth dataset from the procedural parametric head: K training frames "
      "(distinct views, each with its own expression) and test frames at held-out views: the training "
      "expressions (tier observed) and novel expressions in the near/moderate/far tiers (delta = min_k "
      "||beta - beta_k||), with neutral renders and 68 landmarks. The subject performs the expressions in "
      "its own style (style.json: the style and its landmark gap to the generic face model). With --photos "
      "N: instead N photos of the subject (random head pose, size, position and expression over a procedural "
      "background) with their truth (alpha mask, camera, expression, 68 landmarks) for testing a face "
      "tracker.");
  app.add_option("--out,-o", args->out, "Output dataset (or photo-set) directory (created)")->required();
  app.add_option("--identity-seed,--seed", o.identity_seed,
                 "Identity seed (face shape, albedo, views, expressions)")
      ->capture_default_str();
  app.add_flag("--generic-style", o.generic_style,
               "Render the face model's generic expressions instead of the identity's own style");
  app.add_flag(
      "--canonical-shading", o.render.canonical_shading,
      "Shade every point as its neutral canonical point is shaded, so the lighting moves with the skin and "
      "no expression changes it: what a warp of a static field can reproduce (a reference for "
      "scripts/expr_gain_probe.py, not a realistic render)");
  app.add_option("--k", o.num_train, "Number of training frames K")->capture_default_str();
  app.add_option("--res", o.resolution, "Image width = height in pixels")->capture_default_str();
  app.add_option("--test-views", o.test_views, "Held-out test views V")->capture_default_str();
  app.add_option("--novel-per-tier", o.novel_per_tier,
                 "Novel test expressions per tier (near, moderate, far)")
      ->capture_default_str();
  app.add_option("--near", o.near_threshold, "Tier threshold t0: near = (0, t0]")->capture_default_str();
  app.add_option("--far", o.far_threshold, "Tier threshold t1: moderate = (t0, t1], far > t1")
      ->capture_default_str();
  app.add_flag(
      "--diverse", args->diverse,
      "Draw every scene axis per identity seed (skin, lighting, placement, camera, views, resolution, "
      "detail; see scene.json) instead of the classic studio scene; --res pins the resolution");
  app.add_option(
         "--max-res", o.max_drawn_resolution,
         "Largest resolution the drawn resolution axis picks (from 128, 160, 192, 256, 320, 384, 448, 512; "
         "icef bench --validation draws up to 256: --max-res 256 makes its datasets)")
      ->capture_default_str()
      ->check(CLI::Range(128, 4096));
  app.add_option("--vary", args->vary, "Draw these scene axes per identity seed (comma-separated axis names)")
      ->delimiter(',');
  app.add_option("--pin", args->pin, "Keep these scene axes at the classic values (with --diverse)")
      ->delimiter(',');
  app.add_option("--supersample", o.render.supersample, "Samples per pixel along each axis")
      ->capture_default_str();
  app.add_option("--threads", *threads, "Worker threads (0 = all cores)")->capture_default_str();
  CLI::Option* contact =
      app.add_option("--contact-sheet", args->contact_sheet, "Also write a labelled contact sheet PNG here");
  CLI::Option* photos = app.add_option(
      "--photos", *num_photos,
      "Photo-set mode: write N photos with known truth instead of a dataset (DIR/photos/photo_NNN.png, "
      "DIR/truth/alpha_NNN.png, DIR/truth/truth.json, DIR/style.json)");
  app.add_option("--res-photo", args->photo_size, "Photo-set mode: photo size WxH")
      ->capture_default_str()
      ->needs(photos);
  app.add_option("--background-seed", args->background_seed,
                 "Photo-set mode: seed of the procedural backgrounds (0: derived from the identity seed)")
      ->capture_default_str()
      ->needs(photos);
  for (const char* dataset_only :
       {"--k", "--res", "--max-res", "--test-views", "--novel-per-tier", "--near", "--far"})
    photos->excludes(app.get_option(dataset_only));
  photos->excludes(contact);
  for (const char* scene : {"--diverse", "--vary", "--pin"}) photos->excludes(app.get_option(scene));
  CLI::Option* res = app.get_option("--res");
  return [args, photos, threads, num_photos, res]() -> Status {
    SynthAppOptions options = *args;
    options.resolution_given = res->count() > 0;
    if (photos->count() > 0) options.photos = *num_photos;
    options.interactive = StdoutIsTerminal();
    return RunSynth(options, Executor(*threads), std::cout);
  };
}

}  // namespace icef::cli
