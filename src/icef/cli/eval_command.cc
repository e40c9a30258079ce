// icef eval MODEL DATASET --out DIR [--faceid-model DIR] [--lpips-weights FILE] [--expression-scale S]
// [--training-occupancy] [--set model.KEY=VALUE] [--threads N]: app/eval_app.h.
#include <iostream>
#include <memory>

#include "icef/app/eval_app.h"
#include "icef/cli/commands.h"
#include "icef/core/progress.h"

namespace icef::cli {

CommandFn RegisterEval(CLI::App& app) {
  auto o = std::make_shared<EvalAppOptions>();
  auto threads = std::make_shared<int>(0);
  app.description(
      "Evaluate a trained model on a dataset's test frames, per frame and per tier (observed, near, "
      "moderate, "
      "far): PSNR, SSIM, LPIPS (with --lpips-weights) and the neutral floor (PSNR of the ground-truth "
      "neutral: "
      "what a face that does not move scores); expression fidelity in the brow/eye/mouth region (expr_gain: "
      "how much of the true change the render's change reproduces, 1 = all, 0 = none; expr_corr; "
      "expr_gain_coarse, the same at the features' scale, which softness costs little; region_psnr); "
      "identity (face-descriptor distance between each render and the model's own neutral render of the same "
      "view, the ground truth's own such distance, their difference id_excess, and the distance to the "
      "ground "
      "truth). Writes DIR/renders/ and DIR/metrics.json; docs/evaluation.md defines every number.");
  app.add_option("model", o->model, "Model directory (or checkpoint file) written by `icef train`")
      ->required();
  app.add_option("dataset", o->dataset, "Dataset directory with test frames")->required();
  app.add_option("--out,-o", o->out, "Output directory (created)")->required();
  app.add_option(
      "--faceid-model", o->faceid_model,
      "Face-identity model directory (default: $ICEF_FACEID_MODEL or /usr/local/share/icef/face-api)");
  app.add_option("--lpips-weights", o->lpips_weights,
                 "LPIPS weights file (docs/evaluation.md); without it LPIPS is null");
  app.add_option(
         "--expression-scale", o->expression_scale,
         "Render every frame at S x its expression (0: every frame at neutral, a model that renders no "
         "expression; for checking the protocol)")
      ->capture_default_str();
  app.add_flag(
      "--training-occupancy", o->training_occupancy,
      "Place samples with the training occupancy grid (training expressions only, cut to the training "
      "visual hull) instead of the grid of each rendered expression: shows what clipping far "
      "expressions costs");
  app.add_option(
      "--set", o->overrides,
      "Override an inference-only model key, model.KEY=VALUE with KEY render.supersample, "
      "render.sample_factor, sampler.num_samples, "
      "render.transmittance_eps or bf16_inference (repeatable; keys fixed by training are refused)");
  app.add_option("--threads", *threads, "Worker threads (0 = all cores)")->capture_default_str();
  return [o, threads]() -> Status {
    EvalAppOptions options = *o;
    options.interactive = StdoutIsTerminal();
    return RunEval(options, Executor(*threads), std::cout, std::cerr).status();
  };
}

}  // namespace icef::cli
