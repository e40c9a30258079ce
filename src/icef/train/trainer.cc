#include "icef/train/trainer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "icef/io/atomic_file.h"
#include "icef/model/render_image.h"
#include "icef/train/face_depth.h"
#include "icef/train/run_setup.h"

namespace icef {

namespace fs = std::filesystem;

Json TrainSummary::ToJson() const {
  Json j;
  j["method"] = method;
  j["steps"] = steps;
  j["wall_seconds"] = wall_seconds;
  j["final_loss"] = final_loss;
  j["final_batch_psnr"] = final_batch_psnr;
  j["psnr_observed"] = psnr_observed ? Json(*psnr_observed) : Json(nullptr);
  j["observed_frames"] = observed_frames;
  j["samples_per_second"] = samples_per_second;
  j["skipped_steps"] = skipped_steps;
  j["interrupted"] = interrupted;
  j["stop_reason"] = stop_reason;
  j["mouth_cavity_colour"] =
      mouth_cavity_colour
          ? Json::array({(*mouth_cavity_colour)[0], (*mouth_cavity_colour)[1], (*mouth_cavity_colour)[2]})
          : Json(nullptr);
  return j;
}

std::string TrainSummary::BriefReport() const {
  std::ostringstream os;
  os.precision(4);
  os << method << ": " << steps << " steps in " << wall_seconds << " s (" << stop_reason << "), final loss "
     << final_loss << ", batch PSNR " << final_batch_psnr << " dB";
  if (skipped_steps > 0) os << ", steps skipped for a non-finite loss or gradient: " << skipped_steps;
  if (psnr_observed)
    os << ", held-out PSNR (observed tier, " << observed_frames << " frames) " << *psnr_observed << " dB";
  if (mouth_cavity_colour) {
    os.precision(3);
    os << ", mouth cavity colour (" << (*mouth_cavity_colour)[0] << ", " << (*mouth_cavity_colour)[1] << ", "
       << (*mouth_cavity_colour)[2] << ")";
  }
  return os.str();
}

Trainer::Trainer(const Dataset& dataset, fs::path model_dir, RunConfig config, TrainingData data,
                 std::unique_ptr<AvatarModel> model)
    : dataset_(dataset),
      model_dir_(std::move(model_dir)),
      config_(std::move(config)),
      data_(std::move(data)),
      model_(std::move(model)),
      executor_(config_.train.threads) {
  // L_depth's targets: a function of the data and the fit alone, so a resumed run recomputes them.
  const ModelSetup& setup = model_->setup();
  if (config_.train.lambda_depth_prior > 0 && (setup.face_fit || setup.ict_fit)) {
    const Result<std::unique_ptr<FittedSurface>> surface =
        FittedSurface::Create(setup, setup.training_expressions);
    ICEF_CHECK(surface.ok(), surface.status().message());  // the setup holds a fit
    const std::string& region = config_.train.depth_prior_region;
    const std::vector<int64_t> pixels = region == "eyes"   ? EyePixels(dataset_, data_)
                                        : region == "face" ? FacePixels(dataset_, data_)
                                                           : data_.region_pixels();
    data_.SetDepthTargets(FaceModelDepthTargets(**surface, data_, pixels, executor_));
    if (config_.train.depth_prior_views > 0 && config_.train.depth_prior_view_rays > 0) {
      ViewRayOptions views;
      views.views_per_frame = config_.train.depth_prior_views;
      views.max_yaw_deg = config_.train.depth_prior_view_yaw;
      views.max_pitch_deg = config_.train.depth_prior_view_pitch;
      views.seed = static_cast<uint64_t>(config_.train.seed);
      views.region = ViewRegionFromName(config_.train.depth_prior_view_region);
      data_.SetViewRays(FaceModelViewRays(**surface, data_, views, executor_));
    }
  }
  adam_ = std::make_unique<nn::Adam>(MakeAdamOptions(), &model_->store());
  ApplySchedules();
}

nn::AdamOptions Trainer::MakeAdamOptions() const {
  const TrainConfig& t = config_.train;
  nn::AdamOptions o;
  nn::AdamGroup grid, mlp, deform;
  grid.learning_rate = t.lr_grid;
  grid.sparse = true;
  mlp.learning_rate = t.lr_mlp;
  deform.learning_rate = t.lr_deform;
  o.groups = {grid, mlp, deform};  // indices kGridGroup, kMlpGroup, kDeformGroup
  o.schedule = nn::LrSchedule::kExponential;
  o.decay_rate = t.lr_final_factor;
  o.decay_steps = std::max<int64_t>(1, t.steps);
  return o;
}

static Status CheckDatasetMatches(const Dataset& dataset, const ModelSetup& setup, const std::string& where) {
  if (dataset.expression_dim != setup.expression_dim)
    return Status::Error(where + ": expression_dim " + std::to_string(dataset.expression_dim) +
                         " differs from the model's " + std::to_string(setup.expression_dim));
  if (dataset.train.size() != setup.training_expressions.size())
    return Status::Error(where +
                         ": the dataset's training split differs from the one the model was trained on");
  return Status::Ok();
}

Result<std::unique_ptr<Trainer>> Trainer::Create(const Dataset& dataset, const fs::path& model_dir,
                                                 const RunConfig& config) {
  ICEF_RETURN_IF_ERROR(config.Validate());
  // train.start_trials: each trial trains a model of its own as this run would.
  RunConfig trial_config = config;
  trial_config.train.density_start_steps = 0;
  const StartTrialFn run_trial = [&](std::unique_ptr<AvatarModel> model, const TrainingData& data,
                                     int steps) -> Result<std::vector<double>> {
    Trainer trial(dataset, model_dir, trial_config, data, std::move(model));
    std::vector<double> losses;
    for (int step = 0; step < steps; ++step) {
      ICEF_ASSIGN_OR_RETURN(const LossTerms terms, trial.Step());
      losses.push_back(terms.total);
    }
    return losses;
  };
  ICEF_ASSIGN_OR_RETURN(RunSetup run, PrepareRun(dataset, config.model, RunSetupOptions::FromConfig(config),
                                                 run_trial, Executor(config.train.threads)));
  // Only now that the data and the model are good is anything written.
  std::error_code ec;
  fs::create_directories(model_dir, ec);
  if (!fs::is_directory(model_dir))
    return Status::Error(model_dir.string() + ": cannot create the model directory");
  ICEF_RETURN_IF_ERROR(WriteFileAtomic(model_dir / "config.json", FormatJson(config.ToJson())));
  std::unique_ptr<Trainer> trainer(
      new Trainer(dataset, model_dir, config, std::move(run.data), std::move(run.model)));
  trainer->prior_shading_note_ = std::move(run.prior_shading_note);
  trainer->density_start_note_ = std::move(run.density_start_note);
  trainer->start_trials_note_ = std::move(run.start_trials_note);
  return trainer;
}

Result<std::unique_ptr<Trainer>> Trainer::Resume(const Dataset& dataset, const fs::path& model_dir,
                                                 std::optional<int64_t> steps_override,
                                                 std::optional<double> time_budget_override,
                                                 std::optional<int> threads_override) {
  auto configure = [&](const RunConfig& saved) -> Result<RunConfig> {
    RunConfig config = saved;
    if (steps_override) config.train.steps = *steps_override;
    if (time_budget_override) config.train.time_budget_seconds = *time_budget_override;
    if (threads_override) config.train.threads = *threads_override;
    return config;
  };
  return Resume(dataset, model_dir, configure, threads_override.value_or(0));
}

Result<std::unique_ptr<Trainer>> Trainer::Resume(const Dataset& dataset, const fs::path& model_dir,
                                                 const ConfigureResumeFn& configure, int load_threads) {
  ICEF_ASSIGN_OR_RETURN(LoadedModel loaded, LoadModel(model_dir, Executor(load_threads)));
  ICEF_RETURN_IF_ERROR(CheckDatasetMatches(dataset, loaded.model->setup(), dataset.root.string()));
  ICEF_ASSIGN_OR_RETURN(const RunConfig config, configure(loaded.config));
  ICEF_RETURN_IF_ERROR(config.Validate());
  if (WriteConfig(config.model) != WriteConfig(loaded.config.model))
    return Status::Error((model_dir / kCheckpointFile).string() +
                         ": resuming cannot change the model config");
  ICEF_ASSIGN_OR_RETURN(TrainingData data, TrainingData::Load(dataset));
  std::unique_ptr<Trainer> trainer(
      new Trainer(dataset, model_dir, config, std::move(data), std::move(loaded.model)));
  if (!loaded.adam_state.empty()) {
    std::istringstream in(loaded.adam_state);
    ICEF_RETURN_IF_ERROR(
        trainer->adam_->Read(in).WithContext((model_dir / kCheckpointFile).string() + " [adam]"));
  }
  trainer->state_ = loaded.state;
  trainer->ApplySchedules();
  return trainer;
}

void Trainer::ApplySchedules() {
  if (DeformationField* d = model_->residual_field())
    d->SetAnnealing(DeformationAnnealing(config_, state_.step));
  model_->static_field().SetLevelWeights(GridLevelWeights(config_, state_.step));
}

Result<LossTerms> Trainer::Step() {
  const TrainConfig& t = config_.train;
  const uint64_t seed = static_cast<uint64_t>(t.seed);
  ApplySchedules();
  if (state_.step >= t.occupancy_warmup && state_.step % t.occupancy_every == 0)
    model_->UpdateOccupancy(seed, state_.step, executor_);
  RaySampling how;
  how.random_background = t.random_background;
  how.jitter = t.pixel_jitter;
  how.region_fraction = t.region_rays;
  how.view_rays = t.depth_prior_view_rays;
  data_.SampleBatch(t.batch_rays, seed, state_.step, how, &batch_, executor_);
  const LossWeights w = t.Losses(data_.has_alpha());
  const LossTerms terms = model_->TrainForwardBackward(batch_, w, seed, state_.step, executor_);
  // What is non-finite this step ("" when nothing is).
  std::string nonfinite;
  if (const std::string term = terms.FirstNonFinite(); !term.empty())
    nonfinite = "loss term '" + term + "' is not finite";
  if (nonfinite.empty()) {
    // NaN/Inf propagate through * 0; eight independent sums per thread so the loop vectorises.
    const float* g = model_->store().grads();
    std::vector<uint8_t> bad(size_t(executor_.num_threads()), 0);
    ParallelFor(executor_, model_->store().size(), [&](int64_t i0, int64_t i1, int thread) {
      float sums[8] = {};
      int64_t i = i0;
      for (; i + 8 <= i1; i += 8)
        for (int l = 0; l < 8; ++l) sums[l] += g[i + l] * 0.f;
      for (; i < i1; ++i) sums[0] += g[i] * 0.f;
      for (float v : sums) bad[thread] |= !std::isfinite(v);
    });
    if (std::find(bad.begin(), bad.end(), uint8_t{1}) != bad.end())
      nonfinite = "a parameter gradient is not finite";
  }
  const std::string step_name = "step " + std::to_string(state_.step);
  if (!nonfinite.empty() && t.on_nonfinite != "skip")
    return Status::Error(step_name + ": " + nonfinite + "; training stopped, the last checkpoint is kept");
  if (!nonfinite.empty()) {
    // Skip: drop the gradients, leave the parameters and the optimiser state as they are, and
    // advance the step counter so that the next step draws a different batch.
    if (++consecutive_skipped_ > kMaxConsecutiveSkippedSteps)
      return Status::Error(step_name + ": " + nonfinite + ", the " + std::to_string(consecutive_skipped_) +
                           "th non-finite step in a row (train.on_nonfinite = \"skip\" skips at most " +
                           std::to_string(kMaxConsecutiveSkippedSteps) +
                           " in a row); training stopped, the last checkpoint is kept");
    model_->store().ZeroGrads();
    ++state_.skipped_steps;
    ++state_.step;
    ApplySchedules();
    last_step_skipped_ = true;
    return terms;
  }
  consecutive_skipped_ = 0;
  last_step_skipped_ = false;
  adam_->Step(executor_);
  ++state_.step;
  ApplySchedules();  // the model between steps is the model of `state_.step` completed steps
  last_terms_ = terms;
  return terms;
}

Status Trainer::SaveCheckpoint() const {
  ICEF_RETURN_IF_ERROR(
      icef::SaveCheckpoint(model_dir_ / kCheckpointFile, config_, *model_, adam_.get(), state_));
  std::string log;
  for (const auto& line : state_.log) log += line + "\n";
  return WriteFileAtomic(model_dir_ / "train_log.jsonl", log);
}

std::optional<double> Trainer::MeanTierPsnr(const AvatarModel& model, const Dataset& dataset, Tier tier,
                                            const Executor& executor, int* count) {
  double sum = 0;
  int n = 0;
  for (const Frame& f : dataset.test) {
    if (f.tier != tier) continue;
    auto img = LoadFrameImage(dataset, f);
    if (!img.ok()) continue;
    const Image gt = CompositeOver(*img, dataset.background);
    const RenderedImage r = RenderImage(model, f.camera, f.expression, dataset.background, executor);
    sum += PsnrFromMse(MeanSquaredError(r.color, gt));
    ++n;
  }
  if (count) *count = n;
  if (n == 0) return std::nullopt;
  return sum / n;
}

Result<TrainSummary> Trainer::Run(const ProgressFn& progress, const std::atomic<bool>* stop) {
  using Clock = std::chrono::steady_clock;
  const TrainConfig& t = config_.train;
  const auto start = Clock::now();
  const double elapsed_before = state_.elapsed_seconds;
  int64_t samples = 0;
  TrainSummary summary;
  summary.method = config_.model.method;
  summary.stop_reason = "steps";
  auto elapsed = [&] { return elapsed_before + std::chrono::duration<double>(Clock::now() - start).count(); };
  while (state_.step < t.steps) {
    if (stop && stop->load()) {
      summary.interrupted = true;
      summary.stop_reason = "interrupted";
      break;
    }
    if (t.time_budget_seconds > 0 && elapsed() >= t.time_budget_seconds) {
      summary.stop_reason = "time budget";
      break;
    }
    ICEF_ASSIGN_OR_RETURN(const LossTerms terms, Step());
    samples += terms.samples;
    state_.elapsed_seconds = elapsed();
    if (state_.step % t.log_every == 0 || state_.step == t.steps) {
      Json line;
      line["step"] = state_.step;
      line["seconds"] = state_.elapsed_seconds;
      line["loss"] = terms.total;
      for (const LossValue& term : terms.terms) line[term.name] = term.value;
      line["batch_psnr"] = terms.psnr();
      line["occupied"] = model_->occupancy().OccupiedFraction();
      if (last_step_skipped_) line["skipped"] = true;
      if (t.eval_every > 0 && state_.step % t.eval_every == 0) {
        int count = 0;
        const auto psnr = MeanTierPsnr(*model_, dataset_, Tier::kObserved, executor_, &count);
        line["psnr_observed"] = psnr ? Json(*psnr) : Json(nullptr);
      }
      state_.log.push_back(line.dump());
    }
    if (progress) progress({state_.step, t.steps, state_.elapsed_seconds, terms});
    // Not after a skipped step: should the non-finite values persist until training stops, the
    // last checkpoint is still the one of the last good step.
    if (t.checkpoint_every > 0 && state_.step % t.checkpoint_every == 0 && !last_step_skipped_)
      ICEF_RETURN_IF_ERROR(SaveCheckpoint());
  }
  state_.elapsed_seconds = elapsed();
  const double run_seconds = state_.elapsed_seconds - elapsed_before;
  ICEF_RETURN_IF_ERROR(SaveCheckpoint());
  summary.steps = state_.step;
  summary.skipped_steps = state_.skipped_steps;
  summary.wall_seconds = state_.elapsed_seconds;
  summary.final_loss = last_terms_.total;
  summary.final_batch_psnr = last_terms_.psnr();
  summary.samples_per_second = run_seconds > 0 ? samples / run_seconds : 0;
  if (model_->has_mouth_cavity())
    summary.mouth_cavity_colour = {model_->CavityColour(0), model_->CavityColour(1), model_->CavityColour(2)};
  if (!summary.interrupted)
    summary.psnr_observed =
        MeanTierPsnr(*model_, dataset_, Tier::kObserved, executor_, &summary.observed_frames);
  ICEF_RETURN_IF_ERROR(WriteFileAtomic(model_dir_ / "summary.json", FormatJson(summary.ToJson())));
  return summary;
}

}  // namespace icef
