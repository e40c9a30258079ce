// Trains one AvatarModel on one dataset: ray batches from the training frames, the model's
// forward/backward, Adam over the whole slab, the learning-rate schedule, coarse-to-fine
// annealing of the deformation encoding, occupancy-grid updates, periodic atomic checkpoints,
// resume, a NaN/Inf guard, and MODEL/summary.json at the end. It never parses options, writes
// images or draws progress bars: callers observe it through the progress callback.
#pragma once

#include <array>
#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>

#include "icef/data/dataset.h"
#include "icef/nn/adam.h"
#include "icef/train/model_io.h"
#include "icef/train/train_config.h"
#include "icef/train/training_data.h"

namespace icef {

struct TrainSummary {
  std::string method;
  int64_t steps = 0;                    // completed steps
  double wall_seconds = 0;              // training time (all resumed runs together)
  double final_loss = 0;                // total loss of the last step
  double final_batch_psnr = 0;          // PSNR of the last training batch
  std::optional<double> psnr_observed;  // mean PSNR over test frames of tier `observed`
  int observed_frames = 0;
  double samples_per_second = 0;  // field samples per second of training time (this run)
  int64_t skipped_steps = 0;      // steps skipped for a non-finite loss or gradient (all resumed runs)
  bool interrupted = false;       // stopped by a signal before the end
  std::string stop_reason;        // "steps", "time budget" or "interrupted"
  // The learned colour of the face model's mouth cavity (*-prior methods; model/avatar_model.h).
  std::optional<std::array<double, 3>> mouth_cavity_colour;

  Json ToJson() const;
  std::string BriefReport() const;
};

struct TrainProgress {
  int64_t step = 0;
  int64_t total_steps = 0;
  double elapsed_seconds = 0;
  LossTerms terms;
};

// With train.on_nonfinite = "skip", at most this many non-finite steps in a row are skipped; the
// next one stops training.
inline constexpr int kMaxConsecutiveSkippedSteps = 10;

class Trainer {
 public:
  using ProgressFn = std::function<void(const TrainProgress&)>;
  // Turns the checkpoint's config into the config of the continued run (the caller decides what
  // may change; the model config may not).
  using ConfigureResumeFn = std::function<Result<RunConfig>(const RunConfig& checkpoint_config)>;

  // Fresh run: creates model_dir, writes config.json; runs on config.train.threads threads. The
  // dataset must outlive the trainer.
  static Result<std::unique_ptr<Trainer>> Create(const Dataset& dataset,
                                                 const std::filesystem::path& model_dir,
                                                 const RunConfig& config);
  // Continues from model_dir/checkpoint.icef: its config wins, but the overrides may extend the
  // step count or time budget, or change the thread count (results are bit-identical to an
  // uninterrupted run only with the same thread count).
  static Result<std::unique_ptr<Trainer>> Resume(const Dataset& dataset,
                                                 const std::filesystem::path& model_dir,
                                                 std::optional<int64_t> steps_override,
                                                 std::optional<double> time_budget_override,
                                                 std::optional<int> threads_override);
  // Continues from model_dir/checkpoint.icef with the config `configure` returns; the checkpoint
  // is loaded on `load_threads` threads (0 = all cores). Nothing is written here.
  static Result<std::unique_ptr<Trainer>> Resume(const Dataset& dataset,
                                                 const std::filesystem::path& model_dir,
                                                 const ConfigureResumeFn& configure, int load_threads);

  // Runs to the configured step count or time budget, or until *stop becomes true (then a
  // checkpoint is written and summary.interrupted is set). A non-finite loss or gradient stops
  // training with an error naming the step and the term, the last checkpoint intact; with
  // train.on_nonfinite = "skip" the step is skipped instead (no optimiser update, its gradients
  // dropped, the step counter advanced so the next batch differs) unless more than
  // kMaxConsecutiveSkippedSteps steps in a row were non-finite (counted within one run).
  Result<TrainSummary> Run(const ProgressFn& progress, const std::atomic<bool>* stop);

  // One optimiser step (exposed for tests); returns its loss terms (non-finite ones when skipped).
  Result<LossTerms> Step();
  Status SaveCheckpoint() const;

  AvatarModel& model() { return *model_; }
  // Why a model that would use the prior shading trains without it (its light could not be fitted:
  // too few training pixels show the face model's skin); empty otherwise.
  const std::string& prior_shading_note() const { return prior_shading_note_; }
  // What the density start did ("" when train.density_start_steps is 0 or the method has no prior).
  const std::string& density_start_note() const { return density_start_note_; }
  // The unseen-view rays L_depth acts on (train.depth_prior_views; 0 when off).
  size_t num_view_rays() const { return data_.view_rays().size(); }
  // Which initialisation train.start_trials kept and why ("" when start_trials is 1).
  const std::string& start_trials_note() const { return start_trials_note_; }
  const RunConfig& config() const { return config_; }
  int64_t step() const { return state_.step; }

  // Mean PSNR of the model over the dataset's test frames of one tier (nullopt when none).
  static std::optional<double> MeanTierPsnr(const AvatarModel& model, const Dataset& dataset, Tier tier,
                                            const Executor& executor, int* count);

 private:
  Trainer(const Dataset& dataset, std::filesystem::path model_dir, RunConfig config, TrainingData data,
          std::unique_ptr<AvatarModel> model);
  nn::AdamOptions MakeAdamOptions() const;
  void ApplySchedules();

  const Dataset& dataset_;
  std::filesystem::path model_dir_;
  RunConfig config_;
  TrainingData data_;
  std::unique_ptr<AvatarModel> model_;
  std::string prior_shading_note_;
  std::string density_start_note_;
  std::string start_trials_note_;
  std::unique_ptr<nn::Adam> adam_;
  Executor executor_;  // a copy: a thread count
  TrainerState state_;
  TrainRays batch_;
  LossTerms last_terms_;
  int consecutive_skipped_ = 0;     // non-finite steps in a row (on_nonfinite = "skip")
  bool last_step_skipped_ = false;  // the latest Step() was skipped
};

}  // namespace icef
