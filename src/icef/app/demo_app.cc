#include "icef/app/demo_app.h"

#include <sstream>

#include "icef/app/render_app.h"
#include "icef/app/train_app.h"
#include "icef/core/progress.h"
#include "icef/data/dataset.h"
#include "icef/io/gif_writer.h"
#include "icef/io/image.h"
#include "icef/model/model_config.h"
#include "icef/synth/ground_truth_renderer.h"
#include "icef/synth/synthesize.h"

namespace icef {

namespace fs = std::filesystem;

namespace {

// The sweep's renders beside the ground truth of the same expressions and view: compare_NNN.png
// and compare.gif (model left, truth right) in the sweep's directory.
Status WriteSweepComparison(const synth::HeadModel& head, const Camera& camera, const Vec3f& background,
                            const std::vector<RenderedFrameInfo>& frames, const fs::path& dir, int delay_cs,
                            const Executor& executor) {
  std::vector<Image> pairs;
  for (size_t i = 0; i < frames.size(); ++i) {
    ICEF_ASSIGN_OR_RETURN(const Image render, ReadImage(frames[i].color_path));
    const Image truth =
        CompositeOver(synth::RenderGroundTruth(head, camera, frames[i].beta, executor), background);
    Image pair(render.width + truth.width, std::max(render.height, truth.height), 3, 1.f);
    for (int y = 0; y < render.height; ++y)
      for (int x = 0; x < render.width; ++x)
        for (int c = 0; c < 3; ++c) pair.At(x, y, c) = render.At(x, y, std::min(c, render.channels - 1));
    for (int y = 0; y < truth.height; ++y)
      for (int x = 0; x < truth.width; ++x)
        for (int c = 0; c < 3; ++c) pair.At(render.width + x, y, c) = truth.At(x, y, c);
    char name[48];  // "compare_" + up to 20 digits + ".png"
    std::snprintf(name, sizeof name, "compare_%03zu.png", i);
    ICEF_RETURN_IF_ERROR(WritePng(dir / name, pair));
    pairs.push_back(std::move(pair));
  }
  return WriteGif(dir / "compare.gif", pairs, delay_cs);
}

}  // namespace

Status RunDemo(const DemoOptions& given, std::ostream& out) {
  DemoOptions o = given;
  if (o.quick) {
    o.k = 3, o.resolution = 48, o.steps = 60, o.time_budget = 0, o.turntable_frames = 4, o.sweep_frames = 3;
  }
  const fs::path data_dir = o.out / "data", model_dir = o.out / "model";
  const Executor executor(o.threads);

  out << "== 1/4 synthesising subject " << o.identity_seed << " (K = " << o.k << ", " << o.resolution << "x"
      << o.resolution << ") into " << data_dir.string() << "\n";
  synth::SynthOptions so;
  so.out_dir = data_dir;
  so.identity_seed = o.identity_seed;
  so.num_train = o.k;
  so.resolution = o.resolution;
  if (o.quick) so.test_views = 1, so.novel_per_tier = 1;
  {
    ProgressBar bar("synth", synth::SynthImageCount(so), out, StdoutIsTerminal());
    ICEF_RETURN_IF_ERROR(synth::SynthesizeDataset(so, executor, &bar));
    bar.Finish();
  }

  const std::string method = ModelConfig().method;  // the default method (README: which, and why)
  out << "== 2/4 training " << method << " into " << model_dir.string() << "\n";
  TrainAppOptions to;
  to.dataset = data_dir;
  to.out = model_dir;
  to.method = method;
  to.steps = o.steps;
  to.time_budget = o.time_budget;
  to.threads = o.threads;
  to.overwrite = true;
  ICEF_ASSIGN_OR_RETURN(const TrainSummary summary, RunTrain(to, out));

  out << "== 3/4 rendering a turntable\n";
  RenderAppOptions turntable;
  turntable.model = model_dir;
  turntable.out = o.out / "turntable";
  turntable.orbit = o.turntable_frames;
  turntable.threads = o.threads;
  std::ostringstream quiet;
  ICEF_RETURN_IF_ERROR(RunRender(turntable, quiet).status());

  ICEF_ASSIGN_OR_RETURN(const Dataset dataset, LoadDataset(data_dir));
  if (dataset.test.empty()) return Status::Error(data_dir.string() + ": the demo dataset has no test frames");
  const synth::HeadModel head(synth::IdentityParams::FromSeed(o.identity_seed));
  out << "== 4/4 rendering expression sweeps (neutral -> 1.5 x target: past every training expression)\n";
  std::vector<fs::path> sweeps;
  for (const char* target : {"jaw_open=1.0", "smile_left=1.0", "brow_raise_right=1.0"}) {
    RenderAppOptions sweep;
    sweep.model = model_dir;
    const std::string name = std::string(target).substr(0, std::string(target).find('='));
    sweep.out = o.out / ("sweep_" + name);
    sweep.sweep = target;
    sweep.sweep_frames = o.sweep_frames;
    sweep.threads = o.threads;
    sweep.dataset = data_dir;
    sweep.frame = "test:0";  // a held-out view, where the ground truth can be rendered beside it
    ICEF_ASSIGN_OR_RETURN(const auto frames, RunRender(sweep, quiet));
    ICEF_RETURN_IF_ERROR(WriteSweepComparison(head, dataset.test[0].camera, dataset.background, frames,
                                              sweep.out, sweep.gif_delay_cs, executor));
    out << "  " << name << ": kappa " << frames.front().nearest.kappa << " -> " << frames.back().nearest.kappa
        << " (delta " << frames.back().nearest.delta << " at the end)\n";
    sweeps.push_back(sweep.out);
  }

  out << "\nICEF demo finished.\n";
  out << "  " << summary.BriefReport() << "\n";
  out << "  dataset:    " << data_dir.string() << "   (inspect with: build/icef info " << data_dir.string()
      << ")\n";
  out << "  model:      " << model_dir.string() << "   (summary.json, train_log.jsonl, checkpoint.icef)\n";
  out << "  turntable:  " << (o.out / "turntable" / "color.gif").string()
      << "  (+ depth, mask, deformation)\n";
  for (const fs::path& s : sweeps)
    out << "  sweep:      " << (s / "color.gif").string()
        << "  (beside the ground truth: " << (s / "compare.gif").string() << ")\n";
  return Status::Ok();
}

}  // namespace icef
