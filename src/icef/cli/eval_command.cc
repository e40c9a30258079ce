// icef eval MODEL DATASET --out DIR [--faceid-model DIR] [--lpips-weights FILE] [--expression-scale S]
// [--threads N]: renders every test frame of DATASET with the trained MODEL, computes PSNR, SSIM,
// LPIPS (with weights), expression fidelity and identity consistency per frame and per tier
// (eval/evaluate.h), writes the renders and DIR/metrics.json, and prints the per-tier table.
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "icef/cli/commands.h"
#include "icef/eval/evaluate.h"
#include "icef/train/model_io.h"

namespace icef::cli {

CommandFn RegisterEval(CLI::App& app) {
  struct Args {
    std::string model;
    std::string dataset;
    std::string out;
    std::string faceid_model;
    std::string lpips_weights;
    double expression_scale = 1;
    bool training_occupancy = false;
    int threads = 0;
  };
  auto args = std::make_shared<Args>();
  app.description(
      "Evaluate a trained model on a dataset's test frames, per frame and per tier (observed, near, moderate, "
      "far): PSNR, SSIM, LPIPS (with --lpips-weights) and the neutral floor (PSNR of the ground-truth neutral: "
      "what a face that does not move scores); expression fidelity in the brow/eye/mouth region (expr_gain: "
      "how much of the true change the render's change reproduces, 1 = all, 0 = none; expr_corr; region_psnr); "
      "identity (face-descriptor distance between each render and the model's own neutral render of the same "
      "view, the ground truth's own such distance, their difference id_excess, and the distance to the ground "
      "truth). Writes DIR/renders/ and DIR/metrics.json; docs/evaluation.md defines every number.");
  app.add_option("model", args->model, "Model directory (or checkpoint file) written by `icef train`")->required();
  app.add_option("dataset", args->dataset, "Dataset directory with test frames")->required();
  app.add_option("--out,-o", args->out, "Output directory (created)")->required();
  app.add_option("--faceid-model", args->faceid_model,
                 "Face-identity model directory (default: $ICEF_FACEID_MODEL or /usr/local/share/icef/face-api)");
  app.add_option("--lpips-weights", args->lpips_weights, "LPIPS weights file (docs/evaluation.md); without it LPIPS is null");
  app.add_option("--expression-scale", args->expression_scale,
                 "Render every frame at S x its expression (0: every frame at neutral, a model that renders no "
                 "expression; for checking the protocol)")
      ->capture_default_str();
  app.add_flag("--training-occupancy", args->training_occupancy,
               "Place samples with the training occupancy grid (training expressions only, cut to the training "
               "visual hull) instead of the grid of each rendered expression: shows what clipping far "
               "expressions costs");
  app.add_option("--threads", args->threads, "Worker threads (0 = all cores)")->capture_default_str();
  return [args]() -> Status {
    const Executor executor(args->threads);
    ICEF_ASSIGN_OR_RETURN(const Dataset dataset, LoadDataset(args->dataset));
    ICEF_ASSIGN_OR_RETURN(const LoadedModel loaded, LoadModel(args->model, executor));
    ICEF_ASSIGN_OR_RETURN(const std::optional<eval::LpipsNet> lpips, eval::LoadLpipsIfConfigured(args->lpips_weights));
    eval::FaceIdentityOptions fo;
    fo.model_dir = args->faceid_model;
    Result<eval::FaceIdentity> identity = eval::FaceIdentity::Load(fo);
    eval::EvalNetworks networks;
    std::optional<eval::FaceIdentity> identity_holder;
    if (identity.ok()) {
      identity_holder = std::move(identity).value();
      networks.identity = &*identity_holder;
    } else {
      // An explicitly named model must load; the default one may be missing (identity is then null).
      if (!args->faceid_model.empty()) return identity.status();
      networks.identity_note = identity.status().message();
      std::cerr << "icef eval: warning: identity metrics unavailable: " << networks.identity_note << "\n";
    }
    if (lpips) networks.lpips = &*lpips;
    eval::EvalOptions options;
    options.out_dir = args->out;
    options.expression_scale = args->expression_scale;
    if (args->training_occupancy) options.occupancy = RenderOccupancyMode::kTraining;
    ICEF_RETURN_IF_ERROR(options.Validate().WithContext("--expression-scale"));
    ProgressBar progress("eval", static_cast<int64_t>(dataset.test.size()), std::cout, StdoutIsTerminal());
    ICEF_ASSIGN_OR_RETURN(const eval::EvalResult result,
                          eval::EvaluateModel(*loaded.model, dataset, options, networks, executor, &progress));
    const std::filesystem::path metrics = std::filesystem::path(args->out) / "metrics.json";
    ICEF_RETURN_IF_ERROR(eval::WriteMetricsFile(metrics, result));
    std::cout << "method " << result.method << ", " << result.frames.size() << " test frames\n"
              << result.Table() << "wrote " << metrics.string() << " and "
              << (std::filesystem::path(args->out) / "renders").string() << "/\n";
    return Status::Ok();
  };
}

}  // namespace icef::cli
