#include "icef/app/demo_app.h"

#include <sstream>

#include "icef/app/render_app.h"
#include "icef/app/train_app.h"
#include "icef/core/progress.h"
#include "icef/synth/synthesize.h"

namespace icef {

namespace fs = std::filesystem;

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

  out << "== 2/4 training ICEF into " << model_dir.string() << "\n";
  TrainAppOptions to;
  to.dataset = data_dir;
  to.out = model_dir;
  to.method = "icef";
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
    ICEF_ASSIGN_OR_RETURN(const auto frames, RunRender(sweep, quiet));
    out << "  " << name << ": kappa " << frames.front().nearest.kappa << " -> " << frames.back().nearest.kappa
        << " (delta " << frames.back().nearest.delta << " at the end)\n";
    sweeps.push_back(sweep.out);
  }

  out << "\nICEF demo finished.\n";
  out << "  " << summary.BriefReport() << "\n";
  out << "  dataset:    " << data_dir.string() << "   (inspect with: build/icef info " << data_dir.string() << ")\n";
  out << "  model:      " << model_dir.string() << "   (summary.json, train_log.jsonl, checkpoint.icef)\n";
  out << "  turntable:  " << (o.out / "turntable" / "color.gif").string() << "  (+ depth, mask, deformation)\n";
  for (const fs::path& s : sweeps) out << "  sweep:      " << (s / "color.gif").string() << "\n";
  return Status::Ok();
}

}  // namespace icef
