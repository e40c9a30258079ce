#include "icef/app/train_app.h"

#include <algorithm>
#include <iomanip>
#include <sstream>

#include "icef/app/stop_signal.h"
#include "icef/core/progress.h"

namespace icef {
namespace {
// Landmark mirror error (inter-ocular distances) above which the symmetry prior gets a warning.
constexpr float kAsymmetricFace = 0.1f;
}  // namespace

namespace fs = std::filesystem;

namespace {
// `base` (the defaults, or a resumed checkpoint's config), then --config, --set and the flags.
Result<RunConfig> ResolveFrom(RunConfig config, const TrainAppOptions& o) {
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
}  // namespace

Result<RunConfig> ResolveRunConfig(const TrainAppOptions& o) { return ResolveFrom(RunConfig(), o); }

const std::vector<std::string>& ResumableConfigKeys() {
  static const std::vector<std::string> keys = {"train.steps", "train.time_budget_seconds", "train.threads",
                                                "train.on_nonfinite"};
  return keys;
}

Result<RunConfig> ResolveResumeConfig(const TrainAppOptions& o, const RunConfig& saved,
                                      const std::string& checkpoint) {
  ICEF_ASSIGN_OR_RETURN(const RunConfig config, ResolveFrom(saved, o));
  const Json before = saved.ToJson(), after = config.ToJson();
  std::string differ;
  for (const std::string& key : JsonDifferences(before, after)) {
    const auto& allowed = ResumableConfigKeys();
    if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
    std::string pointer = "/" + key;
    std::replace(pointer.begin(), pointer.end(), '.', '/');
    const Json::json_pointer at(pointer);
    differ += (differ.empty() ? "" : ", ") + key + " (checkpoint " +
              (before.contains(at) ? before.at(at).dump() : "-") + ", given " +
              (after.contains(at) ? after.at(at).dump() : "-") + ")";
  }
  if (differ.empty()) return config;
  std::string source = o.config_file ? o.config_file->string() : "--set/--method/--seed";
  std::string allowed;
  for (const std::string& key : ResumableConfigKeys()) allowed += (allowed.empty() ? "" : ", ") + key;
  return Status::Error(checkpoint + ": cannot resume with a different run config (" + source +
                       "): " + differ + "; only " + allowed +
                       " may change when resuming (start afresh with --overwrite)");
}

Result<TrainSummary> RunTrain(const TrainAppOptions& o, std::ostream& out) {
  ICEF_ASSIGN_OR_RETURN(const Dataset dataset, LoadDataset(o.dataset));
  std::error_code ec;
  const bool has_model = fs::exists(o.out / kCheckpointFile, ec);
  std::unique_ptr<Trainer> trainer;
  if (o.resume) {
    if (!has_model)
      return Status::Error(o.out.string() + ": --resume given but there is no checkpoint to resume");
    const std::string checkpoint = (o.out / kCheckpointFile).string();
    auto configure = [&](const RunConfig& saved) { return ResolveResumeConfig(o, saved, checkpoint); };
    ICEF_ASSIGN_OR_RETURN(trainer, Trainer::Resume(dataset, o.out, configure, o.threads.value_or(0)));
  } else {
    if (has_model && !o.overwrite)
      return Status::Error(o.out.string() +
                           ": already holds a trained model; use --resume to continue it, "
                           "--overwrite to start afresh, or another --out");
    ICEF_ASSIGN_OR_RETURN(const RunConfig config, ResolveRunConfig(o));
    ICEF_ASSIGN_OR_RETURN(trainer, Trainer::Create(dataset, o.out, config));
  }
  const RunConfig& config = trainer->config();
  out << "icef train: " << config.model.method << " on " << o.dataset.string() << " (" << dataset.train.size()
      << " training frames), " << config.train.steps << " steps";
  if (config.train.time_budget_seconds > 0) out << " or " << config.train.time_budget_seconds << " s";
  out << (o.resume ? ", resuming at step " + std::to_string(trainer->step()) : "") << "\n";
  if (!trainer->start_trials_note().empty()) out << trainer->start_trials_note() << "\n";
  const ModelSetup& setup = trainer->model().setup();
  if (setup.face_fit || setup.ict_fit) {
    if (setup.face_fit) {
      out << setup.face_fit->BriefReport() << "\n";
    } else {
      out << "ICT-FaceKit fit: landmark RMS " << setup.ict_fit->rms_iod << " IOD over the training frames, "
          << setup.ict_fit->identity.size() << " identity coefficients\n";
    }
    if (const std::optional<Vec3f>& light = trainer->model().prior_light())
      out << "prior shading: light [" << light->x() << ", " << light->y() << ", " << light->z()
          << "] (strength " << light->norm() << ", fitted to the training images' skin)\n";
    if (!trainer->density_start_note().empty()) out << trainer->density_start_note() << "\n";
    if (trainer->num_view_rays() > 0)
      out << "depth prior: " << trainer->num_view_rays() << " rays from " << config.train.depth_prior_views
          << " unseen views per training frame, " << config.train.depth_prior_view_rays << " per step\n";
    if (!trainer->prior_shading_note().empty())
      out << "prior shading: off, no light fitted (" << trainer->prior_shading_note() << ")\n";
    if ((setup.face_fit && setup.face_fit->Poor()) || (setup.ict_fit && setup.ict_fit->rms_iod > 0.1))
      out << "warning: the face model fits the landmarks poorly (RMS above 0.1 inter-ocular distances): the "
             "prior will pull expressions to the wrong places; check the dataset's landmarks and expression "
             "vectors\n";
  }
  if (config.train.lambda_symmetry > 0) {
    const std::optional<SymmetryPlane>& plane = trainer->model().symmetry_plane();
    if (!plane) {
      out << "symmetry prior: off, the landmarks give no left-right symmetry plane\n";
    } else {
      std::ostringstream line;
      line << "symmetry prior: landmark pairs mirror onto each other within " << std::setprecision(2)
           << plane->residual() << " inter-ocular distances";
      if (plane->residual() > kAsymmetricFace)
        line << " (a clearly asymmetric face: consider train.lambda_symmetry=0)";
      out << line.str() << "\n";
    }
  }
  out << std::flush;
  ProgressBar bar("train", config.train.steps, out, !o.quiet && StdoutIsTerminal());
  bar.Update(trainer->step());
  auto progress = [&](const TrainProgress& p) {
    std::ostringstream status;
    status << std::fixed << std::setprecision(4) << "loss " << p.terms.total << std::setprecision(2)
           << " psnr " << p.terms.psnr();
    bar.Update(p.step, status.str());
  };
  const std::atomic<bool>* stop = InstallStopHandlers();
  ICEF_ASSIGN_OR_RETURN(const TrainSummary summary, trainer->Run(progress, stop));
  bar.Finish("loss " + std::to_string(summary.final_loss));
  out << summary.BriefReport() << "\n";
  out << "model: " << (o.out / kCheckpointFile).string() << "\nsummary: " << (o.out / "summary.json").string()
      << "\n";
  if (summary.interrupted)
    out << "interrupted: resume with `icef train " << o.dataset.string() << " --out " << o.out.string()
        << " --resume`\n";
  return summary;
}

}  // namespace icef
