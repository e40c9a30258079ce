#include "icef/train/run_setup.h"

#include <cmath>
#include <sstream>

#include "icef/core/rng.h"
#include "icef/face/expression.h"
#include "icef/model/face_prior.h"
#include "icef/model/ict_prior.h"
#include "icef/model/method.h"
#include "icef/model/prior_light.h"
#include "icef/train/visual_hull.h"

namespace icef {

RunSetupOptions RunSetupOptions::FromConfig(const RunConfig& config) {
  const ModelConfig& m = config.model;
  const TrainConfig& t = config.train;
  RunSetupOptions o;
  o.fit_face = UsesFacePrior(m.ParsedMethod());
  o.fit_style = m.prior_style;
  o.fit_light = m.prior_shading;
  o.visual_hull = m.visual_hull.enabled;
  o.hull_margin_px = m.visual_hull.margin_px;
  o.hull_min_views = m.visual_hull.min_views;
  o.hull_resolution = m.occupancy.resolution;
  o.seed = static_cast<uint64_t>(t.seed);
  o.start_trials = t.start_trials;
  o.start_trial_steps = t.start_trial_steps;
  o.density_start.steps = t.density_start_steps;
  o.density_start.erosion = static_cast<float>(t.density_start_erosion);
  o.density_start.inside_log_density = static_cast<float>(t.density_start_log_density);
  return o;
}

Status RunSetupOptions::Validate() const {
  if (hull_margin_px < 0 || hull_min_views < 0 || hull_resolution < 1)
    return Status::Error("run setup: hull_margin_px and hull_min_views must be >= 0, hull_resolution >= 1");
  if (start_trials < 1 || start_trial_steps < 4)
    return Status::Error("run setup: start_trials must be >= 1 and start_trial_steps >= 4");
  if (density_start.steps < 0 || !(density_start.erosion >= 0) ||
      !std::isfinite(density_start.inside_log_density))
    return Status::Error(
        "run setup: the density start needs steps >= 0, erosion >= 0 and a finite log-density");
  return Status::Ok();
}

std::string RunSetupOptions::ToString() const {
  std::ostringstream os;
  os << "RunSetupOptions(fit_face=" << fit_face << ", fit_style=" << fit_style << ", fit_light=" << fit_light
     << ", visual_hull=" << visual_hull << ", hull_margin_px=" << hull_margin_px
     << ", hull_min_views=" << hull_min_views << ", hull_resolution=" << hull_resolution << ", seed=" << seed
     << ", start_trials=" << start_trials << ", start_trial_steps=" << start_trial_steps
     << ", density_start_steps=" << density_start.steps << ")";
  return os.str();
}

Result<std::string> FitFacePrior(const Dataset& dataset, const RunSetupOptions& options,
                                 const Executor& executor, ModelSetup* setup) {
  if (options.fit_face) {
    // ICT-FaceKit's model file is read only for datasets not in the procedural model's expressions.
    if (dataset.expression_names != face::ExpressionNames()) {
      ICEF_ASSIGN_OR_RETURN(const std::shared_ptr<const face::IctModel> ict, face::IctModel::LoadDefault());
      if (IsIctExpressionSpace(*ict, dataset.expression_names)) {
        Result<IctFaceFit> fit = FitIctToDataset(*ict, dataset);
        if (!fit.ok()) return fit.status().WithContext("face model fit");
        setup->ict_fit = std::move(fit).value();
        if (!options.fit_light) return std::string();
        Result<PriorLightFit> light = FitPriorLight(dataset, *setup->ict_fit);
        if (!light.ok()) return light.status().message();
        setup->prior_light = light->light;
        return std::string();
      }
    }
    face::FaceFitOptions fit_options;
    fit_options.fit_style = options.fit_style;
    Result<face::FaceFit> fit = FitFaceModelToDataset(dataset, fit_options);
    if (!fit.ok()) return fit.status().WithContext("face model fit");
    setup->face_fit = std::move(fit).value();
  }
  if (!options.fit_light || !setup->face_fit) return std::string();
  // Without a light (tiny images) the model trains unshaded: the shading is a refinement, and the
  // rest of the prior still applies.
  Result<PriorLightFit> light = FitPriorLight(dataset, *setup->face_fit, executor);
  if (!light.ok()) return light.status().message();
  setup->prior_light = light->light;
  return std::string();
}

std::vector<uint8_t> VisualHull(const TrainingData& data, const Aabb& aabb, const RunSetupOptions& options,
                                const Executor& executor) {
  if (!options.visual_hull || !data.has_alpha()) return {};
  std::vector<Image> alphas;
  for (int k = 0; k < data.num_frames(); ++k) alphas.push_back(data.Alpha(k));
  VisualHullOptions hull;
  hull.margin_px = options.hull_margin_px;
  hull.min_views = options.hull_min_views > 0 ? options.hull_min_views : (data.num_frames() + 1) / 2;
  return VisualHullCells(aabb, options.hull_resolution, data.cameras(), alphas, hull, executor);
}

uint64_t StartTrialSeed(uint64_t seed, int trial) {
  return trial == 0 ? seed : Mix64(seed ^ Mix64(StreamId("start_trial") + uint64_t(trial)));
}

Result<StartTrialChoice> ChooseStartTrial(const ModelFactory& make_model, const TrainingData& data,
                                          const RunSetupOptions& options, const StartTrialFn& run_trial) {
  StartTrialChoice choice;
  if (options.start_trials <= 1) return choice;
  const int steps = options.start_trial_steps;
  double best_loss = 0;
  std::ostringstream os;
  os.precision(4);
  os << "start trials: batch loss over steps " << steps - steps / 4 << "-" << steps << " of";
  for (int t = 0; t < options.start_trials; ++t) {
    const std::string trial_name = "start trial " + std::to_string(t);
    Result<std::unique_ptr<AvatarModel>> model = make_model(StartTrialSeed(options.seed, t));
    if (!model.ok()) return model.status().WithContext(trial_name);
    Result<std::vector<double>> losses = run_trial(std::move(model).value(), data, steps);
    if (!losses.ok()) return losses.status().WithContext(trial_name);
    double sum = 0;
    int counted = 0;
    for (int step = steps - steps / 4; step < steps && step < static_cast<int>(losses->size()); ++step) {
      sum += (*losses)[step];
      ++counted;
    }
    const double loss = counted > 0 ? sum / counted : 0;
    os << (t ? ", " : " ") << "trial " << t << " " << loss;
    if (t == 0 || loss < best_loss) {
      best_loss = loss;
      choice.trial = t;
    }
  }
  os << "; training starts from trial " << choice.trial << "'s initialisation";
  choice.note = os.str();
  return choice;
}

Result<std::string> SeedDensity(const RunSetupOptions& options, AvatarModel* model,
                                const Executor& executor) {
  if (options.density_start.steps <= 0 || !model->setup().face_fit) return std::string();
  Result<double> mse = SeedDensityFromFaceModel(*model->setup().face_fit, options.density_start, options.seed,
                                                model, executor);
  if (!mse.ok()) return mse.status().WithContext("density start");
  std::ostringstream os;
  os.precision(3);
  os << "density start: " << options.density_start.steps
     << " steps on the fitted head, log-density RMS error " << std::sqrt(*mse);
  return os.str();
}

Result<RunSetup> PrepareRun(const Dataset& dataset, const ModelConfig& model_config,
                            const RunSetupOptions& options, const StartTrialFn& run_trial,
                            const Executor& executor) {
  ICEF_RETURN_IF_ERROR(options.Validate());
  RunSetup run;
  ICEF_ASSIGN_OR_RETURN(run.data, TrainingData::Load(dataset));
  Result<ModelSetup> setup = ModelSetup::FromDataset(dataset, executor);
  if (!setup.ok()) return setup.status().WithContext("model setup");
  ICEF_ASSIGN_OR_RETURN(run.prior_shading_note, FitFacePrior(dataset, options, executor, &*setup));
  run.hull_cells = VisualHull(run.data, setup->aabb, options, executor);
  // A model initialised from `init_seed`, its occupancy carved by the visual hull.
  const ModelFactory make_model = [&](uint64_t init_seed) -> Result<std::unique_ptr<AvatarModel>> {
    Result<std::unique_ptr<AvatarModel>> model = AvatarModel::Create(model_config, *setup, executor);
    if (!model.ok()) return model.status().WithContext("model");
    (*model)->Initialize(init_seed);
    if (!run.hull_cells.empty())
      ICEF_RETURN_IF_ERROR((*model)->occupancy().SetAllowed(run.hull_cells).WithContext("visual hull"));
    return model;
  };
  ICEF_ASSIGN_OR_RETURN(const StartTrialChoice choice,
                        ChooseStartTrial(make_model, run.data, options, run_trial));
  run.start_trial = choice.trial;
  run.start_trials_note = choice.note;
  ICEF_ASSIGN_OR_RETURN(run.model, make_model(StartTrialSeed(options.seed, choice.trial)));
  ICEF_ASSIGN_OR_RETURN(run.density_start_note, SeedDensity(options, run.model.get(), executor));
  return run;
}

}  // namespace icef
