#include "icef/app/train_app.h"

#include <iomanip>
#include <sstream>

#include "icef/app/stop_signal.h"
#include "icef/core/progress.h"

namespace icef {

namespace fs = std::filesystem;

Result<RunConfig> ResolveRunConfig(const TrainAppOptions& o) {
  RunConfig config;
  if (o.config_file) {
    ICEF_ASSIGN_OR_RETURN(config, RunConfig::FromFile(*o.config_file));
  }
  for (const std::string& s : o.overrides) ICEF_RETURN_IF_ERROR(config.ApplyOverride(s));
  if (o.method) {
    ICEF_RETURN_IF_ERROR(ParseMethod(*o.method).status().WithContext("--method"));
    config.model.method = *o.method;
  }
  if (o.steps) config.train.steps = *o.steps;
  if (o.time_budget) config.train.time_budget_seconds = *o.time_budget;
  if (o.seed) config.train.seed = *o.seed;
  if (o.threads) config.train.threads = *o.threads;
  ICEF_RETURN_IF_ERROR(config.Validate().WithContext("run config"));
  return config;
}

Result<TrainSummary> RunTrain(const TrainAppOptions& o, std::ostream& out) {
  ICEF_ASSIGN_OR_RETURN(const Dataset dataset, LoadDataset(o.dataset));
  std::error_code ec;
  const bool has_model = fs::exists(o.out / kCheckpointFile, ec);
  std::unique_ptr<Trainer> trainer;
  if (o.resume) {
    if (!has_model) return Status::Error(o.out.string() + ": --resume given but there is no checkpoint to resume");
    ICEF_ASSIGN_OR_RETURN(trainer,
                          Trainer::Resume(dataset, o.out, o.steps, o.time_budget, o.threads));
  } else {
    if (has_model && !o.overwrite)
      return Status::Error(o.out.string() + ": already holds a trained model; use --resume to continue it, "
                                            "--overwrite to start afresh, or another --out");
    ICEF_ASSIGN_OR_RETURN(const RunConfig config, ResolveRunConfig(o));
    ICEF_ASSIGN_OR_RETURN(trainer, Trainer::Create(dataset, o.out, config));
  }
  const RunConfig& config = trainer->config();
  out << "icef train: " << config.model.method << " on " << o.dataset.string() << " (" << dataset.train.size()
      << " training frames), " << config.train.steps << " steps";
  if (config.train.time_budget_seconds > 0) out << " or " << config.train.time_budget_seconds << " s";
  out << (o.resume ? ", resuming at step " + std::to_string(trainer->step()) : "") << "\n" << std::flush;
  ProgressBar bar("train", config.train.steps, out, !o.quiet && StdoutIsTerminal());
  bar.Update(trainer->step());
  auto progress = [&](const TrainProgress& p) {
    std::ostringstream status;
    status << std::fixed << std::setprecision(4) << "loss " << p.terms.total << std::setprecision(2) << " psnr "
           << p.terms.psnr();
    bar.Update(p.step, status.str());
  };
  const std::atomic<bool>* stop = InstallStopHandlers();
  ICEF_ASSIGN_OR_RETURN(const TrainSummary summary, trainer->Run(progress, stop));
  bar.Finish("loss " + std::to_string(summary.final_loss));
  out << summary.BriefReport() << "\n";
  out << "model: " << (o.out / kCheckpointFile).string() << "\nsummary: " << (o.out / "summary.json").string()
      << "\n";
  if (summary.interrupted) out << "interrupted: resume with `icef train " << o.dataset.string() << " --out "
                               << o.out.string() << " --resume`\n";
  return summary;
}

}  // namespace icef
