// icef synth --out DIR [--identity-seed N --generic-style --k K --res R --test-views V
//   --novel-per-tier N --near T0 --far T1 --threads T --contact-sheet FILE.png]: renders a synthetic
// ground-truth dataset of one procedural identity (see synth/synthesize.h) and prints the
// identity's expression-style gap (also in DIR/style.json).
// icef synth --photos N --out DIR [--identity-seed N --generic-style --res-photo WxH
//   --background-seed S --supersample S --threads T]: instead, N photos of the identity at random
// head poses, sizes, positions and expressions over procedural backgrounds, with their truth
// (DIR/photos/, DIR/truth/alpha_NNN.png, DIR/truth/truth.json, DIR/style.json; synth/photo_set.h),
// for testing a face tracker.
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "icef/cli/commands.h"
#include "icef/synth/contact_sheet.h"
#include "icef/synth/photo_set.h"
#include "icef/synth/synthesize.h"

namespace icef::cli {

namespace {

struct SynthArgs {
  synth::SynthOptions options;
  std::string out;
  int threads = 0;
  std::string contact_sheet;
  int photos = 0;  // the photo-set mode's N (the mode is on when --photos is given)
  std::string photo_size = "480x640";
  uint64_t background_seed = 0;
};

Status RunPhotoSet(const SynthArgs& args) {
  synth::PhotoSetOptions options;
  options.identity_seed = args.options.identity_seed;
  options.generic_style = args.options.generic_style;
  options.num_photos = args.photos;
  options.render = args.options.render;
  options.background_seed = args.background_seed;
  char x = 0, extra = 0;
  if (std::sscanf(args.photo_size.c_str(), "%d%c%d%c", &options.width, &x, &options.height, &extra) != 3 ||
      (x != 'x' && x != 'X'))
    return Status::Error("--res-photo: expected WxH (e.g. 480x640), got '" + args.photo_size + "'");
  ICEF_RETURN_IF_ERROR(options.Validate());
  const Executor executor(args.threads);
  ICEF_ASSIGN_OR_RETURN(const std::vector<synth::SynthPhoto> photos,
                        synth::RenderPhotoSet(options, executor));
  ICEF_RETURN_IF_ERROR(synth::WritePhotoSet(options, photos, args.out));
  std::cout << "wrote " << args.out << ": " << photos.size() << " photos (" << options.width << "x"
            << options.height << ") with their truth (" << synth::kPhotoTruthFile << ")\n";
  return Status::Ok();
}

}  // namespace

CommandFn RegisterSynth(CLI::App& app) {
  auto args = std::make_shared<SynthArgs>();
  synth::SynthOptions& o = args->options;
  app.description(
      "Render a synthetic ground-truth dataset from the procedural parametric head: K training "
      "frames (distinct views, each with its own expression) and test frames at held-out views: "
      "the training expressions (tier observed) and novel expressions in the near/moderate/far "
      "tiers (delta = min_k ||beta - beta_k||), with neutral renders and 68 landmarks. The subject "
      "performs the expressions in its own style (style.json: the style and its landmark gap to the "
      "generic face model). With --photos N: instead N photos of the subject (random head pose, size, "
      "position and expression over a procedural background) with their truth (alpha mask, camera, "
      "expression, 68 landmarks) for testing a face tracker.");
  app.add_option("--out,-o", args->out, "Output dataset (or photo-set) directory (created)")->required();
  app.add_option("--identity-seed,--seed", o.identity_seed,
                 "Identity seed (face shape, albedo, views, expressions)")
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
  CLI::Option* contact =
      app.add_option("--contact-sheet", args->contact_sheet, "Also write a labelled contact sheet PNG here");
  CLI::Option* photos = app.add_option(
      "--photos", args->photos,
      "Photo-set mode: write N photos with known truth instead of a dataset (DIR/photos/photo_NNN.png, "
      "DIR/truth/alpha_NNN.png, DIR/truth/truth.json, DIR/style.json)");
  app.add_option("--res-photo", args->photo_size, "Photo-set mode: photo size WxH")
      ->capture_default_str()
      ->needs(photos);
  app.add_option("--background-seed", args->background_seed,
                 "Photo-set mode: seed of the procedural backgrounds (0: derived from the identity seed)")
      ->capture_default_str()
      ->needs(photos);
  for (const char* dataset_only : {"--k", "--res", "--test-views", "--novel-per-tier", "--near", "--far"})
    photos->excludes(app.get_option(dataset_only));
  photos->excludes(contact);
  return [args, photos]() -> Status {
    if (photos->count() > 0) return RunPhotoSet(*args);
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
