// The setup stage between data and model: what a fresh run does before its first step. From a
// dataset and the run config it loads the training frames, fits the face model (methods on the
// face-model prior) and the prior shading's light, carves the occupancy grid to the visual hull of
// the training masks, tries the start initialisations (train.start_trials) and seeds the density
// from the fitted head (train.density_start_steps). It writes nothing: Trainer::Create trains the
// model it returns and prints its notes.
//
//   dataset --> training frames, ModelSetup --> face fit --> light --> hull --> start trials
//           --> the model (the best trial's initialisation, carved) --> density start
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/data/dataset.h"
#include "icef/model/avatar_model.h"
#include "icef/train/density_start.h"
#include "icef/train/train_config.h"
#include "icef/train/training_data.h"

namespace icef {

// What the stage does; FromConfig derives it from a run config.
struct RunSetupOptions {
  bool fit_face = false;        // fit the face model to the training frames (methods on the face-model prior)
  bool fit_style = true;        // the fit also fits the subject's expression style (model.prior_style)
  bool fit_light = false;       // fit the prior shading's light to the fitted face (model.prior_shading)
  bool visual_hull = true;      // carve the occupancy grid to the masks' visual hull (images with alpha only)
  int hull_margin_px = 2;       // the hull's footprint dilation, pixels
  int hull_min_views = 0;       // cells fewer training views see are carved (0 = ceil(K / 2))
  int hull_resolution = 64;     // cells per axis of the hull: the occupancy grid's resolution
  uint64_t seed = 0;            // the run's root seed: trial 0's initialisation and the density start's draws
  int start_trials = 1;         // initialisations tried (1 = the seed's alone)
  int start_trial_steps = 100;  // steps each trial trains; the last quarter's batch loss picks one
  DensityStartOptions density_start;  // density_start.steps = 0: the uniform start (face fit only)

  static RunSetupOptions FromConfig(const RunConfig& config);
  Status Validate() const;
  std::string ToString() const;
};

// What the stage hands the trainer.
struct RunSetup {
  TrainingData data;                   // the training frames in memory
  std::unique_ptr<AvatarModel> model;  // initialised, carved to the hull, density seeded
  std::vector<uint8_t> hull_cells;     // [R^3] the hull (1 = may be occupied); empty: no hull
  int start_trial = 0;                 // the trial whose initialisation the model has
  // Why the prior shading trains without its light (too few pixels show the fitted skin); "" otherwise.
  std::string prior_shading_note;
  std::string start_trials_note;   // which trial was kept and why ("" with one trial)
  std::string density_start_note;  // what the density start did ("" without one)
};

// Trains `model` on `data` for `steps` steps as the run would and returns each step's total loss
// (train.start_trials; the trainer supplies it).
using StartTrialFn = std::function<Result<std::vector<double>>(std::unique_ptr<AvatarModel> model,
                                                               const TrainingData& data, int steps)>;

// Runs the stage. An error names the step it came from ("face model fit: ...", "start trial 2: ...").
Result<RunSetup> PrepareRun(const Dataset& dataset, const ModelConfig& model_config,
                            const RunSetupOptions& options, const StartTrialFn& run_trial,
                            const Executor& executor);

// The steps PrepareRun takes, in its order.

// Fits the face model into setup->face_fit when options.fit_face, then (options.fit_light) the prior
// shading's light into setup->prior_light. Returns the note on a light that could not be fitted
// (the model then trains unshaded), "" otherwise.
Result<std::string> FitFacePrior(const Dataset& dataset, const RunSetupOptions& options,
                                 const Executor& executor, ModelSetup* setup);

// The visual hull of the training masks over `aabb` (empty when off or the images have no alpha).
std::vector<uint8_t> VisualHull(const TrainingData& data, const Aabb& aabb, const RunSetupOptions& options,
                                const Executor& executor);

// Trial t's initialisation seed: the run's seed for trial 0, a derived one for the others.
uint64_t StartTrialSeed(uint64_t seed, int trial);

// A fresh model initialised from a seed (PrepareRun's: carved to the hull).
using ModelFactory = std::function<Result<std::unique_ptr<AvatarModel>>(uint64_t init_seed)>;

// Which initialisation training starts from.
struct StartTrialChoice {
  int trial = 0;     // the kept trial: the lowest mean batch loss over the last quarter of its steps
  std::string note;  // "" with one trial
};

// Trains options.start_trials initialisations for options.start_trial_steps steps each and keeps the
// one with the lowest late loss (the first of equal ones): the same choice every time.
Result<StartTrialChoice> ChooseStartTrial(const ModelFactory& make_model, const TrainingData& data,
                                          const RunSetupOptions& options, const StartTrialFn& run_trial);

// Seeds the model's density from its face fit (options.density_start.steps > 0 and a fit); returns
// the note ("" when there was nothing to do).
Result<std::string> SeedDensity(const RunSetupOptions& options, AvatarModel* model, const Executor& executor);

}  // namespace icef
