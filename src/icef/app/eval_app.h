// `icef eval MODEL DATASET --out DIR`: renders every test frame of DATASET with the trained MODEL,
// computes PSNR, SSIM, LPIPS (with weights), expression fidelity and identity consistency per frame
// and per tier (eval/evaluate.h), writes the renders and DIR/metrics.json, and prints the per-tier
// table. The face-identity network is optional unless named: without it the identity metrics are
// null and a warning says why.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/eval/evaluate.h"

namespace icef {

struct EvalAppOptions {
  std::filesystem::path model;         // model directory or checkpoint file written by `icef train`
  std::filesystem::path dataset;       // dataset directory with test frames
  std::filesystem::path out;           // output directory (created): renders/ and metrics.json
  std::filesystem::path faceid_model;  // face-identity model directory (empty: the default, may be missing)
  std::string lpips_weights;           // LPIPS weights file (empty: LPIPS is null)
  double expression_scale = 1;         // render every frame at this multiple of its expression
  bool training_occupancy = false;     // place samples with the training occupancy grid
  std::vector<std::string> overrides;  // "model.KEY=VALUE" of inference-only keys (model/trained_model.h)
  bool interactive = false;            // redraw the progress bar in place (stdout is a terminal)

  // Errors name the option (--expression-scale ...).
  Status Validate() const;
};

// Evaluates, writes out/metrics.json and out/renders/, prints the summary on `out` and the warning
// about missing identity metrics on `err`.
Result<eval::EvalResult> RunEval(const EvalAppOptions& options, const Executor& executor, std::ostream& out,
                                 std::ostream& err);

}  // namespace icef
