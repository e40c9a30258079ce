// icef synth --out DIR [--identity-seed N --generic-style --k K --res R --test-views V
//   --novel-per-tier N --near T0 --far T1 --threads T --contact-sheet FILE.png]: renders a synthetic
// ground-truth dataset of one procedural identity (see synth/synthesize.h) and prints the
// identity's expression-style gap (also in DIR/style.json).
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "icef/cli/commands.h"
#include "icef/synth/contact_sheet.h"
#include "icef/synth/synthesize.h"

namespace icef::cli {

CommandFn RegisterSynth(CLI::App& app) {
  struct Args {
    synth::SynthOptions options;
    std::string out;
    int threads = 0;
    std::string contact_sheet;
  };
  auto args = std::make_shared<Args>();
  synth::SynthOptions& o = args->options;
  app.description(
      "Render a synthetic ground-truth dataset from the procedural parametric head: K training "
      "frames (distinct views, each with its own expression) and test frames at held-out views: "
      "the training expressions (tier observed) and novel expressions in the near/moderate/far "
      "tiers (delta = min_k ||beta - beta_k||), with neutral renders and 68 landmarks. The subject "
      "performs the expressions in its own style (style.json: the style and its landmark gap to the "
      "generic face model).");
  app.add_option("--out,-o", args->out, "Output dataset directory (created)")->required();
  app.add_option("--identity-seed", o.identity_seed, "Identity seed (face shape, albedo, views, expressions)")
      ->capture_default_str();
  app.add_flag("--generic-style", o.generic_style,
               "Render the face model's generic expressions instead of the identity's own style");
  app.add_option("--k", o.num_train, "Number of training frames K")->capture_default_str();
  app.add_option("--res", o.resolution, "Image width = height in pixels")->capture_default_str();
  app.add_option("--test-views", o.test_views, "Held-out test views V")->capture_default_str();
  app.add_option("--novel-per-tier", o.novel_per_tier, "Novel test expressions per tier (near, moderate, far)")
      ->capture_default_str();
  app.add_option("--near", o.near_threshold, "Tier threshold t0: near = (0, t0]")->capture_default_str();
  app.add_option("--far", o.far_threshold, "Tier threshold t1: moderate = (t0, t1], far > t1")->capture_default_str();
  app.add_option("--supersample", o.render.supersample, "Samples per pixel along each axis")->capture_default_str();
  app.add_option("--threads", args->threads, "Worker threads (0 = all cores)")->capture_default_str();
  app.add_option("--contact-sheet", args->contact_sheet, "Also write a labelled contact sheet PNG here");
  return [args]() -> Status {
    synth::SynthOptions options = args->options;
    options.out_dir = args->out;
    ICEF_RETURN_IF_ERROR(options.Validate());
    const Executor executor(args->threads);
    ProgressBar progress("synth", synth::SynthImageCount(options), std::cout, StdoutIsTerminal());
    Dataset dataset;
    face::StyleGap gap;
    ICEF_RETURN_IF_ERROR(synth::SynthesizeDataset(options, executor, &progress, &dataset, &gap));
    std::cout << "wrote " << args->out << ": " << dataset.train.size() << " train + " << dataset.test.size()
              << " test frames (" << options.resolution << "x" << options.resolution << ")\n";
    char mean[32];
    std::snprintf(mean, sizeof mean, "%.3f", gap.mean);
    std::cout << "expression style: " << (options.generic_style ? "generic (--generic-style)" : "the identity's own")
              << "; style gap " << mean << " (landmark deviation from the generic expressions at weight 1, "
              << "as a fraction of their motion; mean over " << gap.num_measured << " expressions; "
              << synth::kStyleInfoFile << ")\n";
    if (!args->contact_sheet.empty()) {
      ICEF_ASSIGN_OR_RETURN(const Image sheet, synth::MakeContactSheet(dataset));
      ICEF_RETURN_IF_ERROR(WritePng(args->contact_sheet, sheet));
      std::cout << "wrote contact sheet " << args->contact_sheet << "\n";
    }
    return Status::Ok();
  };
}

}  // namespace icef::cli
