#include "icef/app/eval_app.h"

#include <optional>

#include "icef/core/progress.h"
#include "icef/data/dataset.h"
#include "icef/eval/face_identity.h"
#include "icef/eval/lpips.h"
#include "icef/model/trained_model.h"

namespace icef {

namespace {
eval::EvalOptions MakeEvalOptions(const EvalAppOptions& o) {
  eval::EvalOptions options;
  options.out_dir = o.out;
  options.expression_scale = o.expression_scale;
  if (o.training_occupancy) options.occupancy = RenderOccupancyMode::kTraining;
  return options;
}
}  // namespace

Status EvalAppOptions::Validate() const {
  if (model.empty()) return Status::Error("a model directory is required");
  if (dataset.empty()) return Status::Error("a dataset directory is required");
  if (out.empty()) return Status::Error("--out is required");
  return MakeEvalOptions(*this).Validate().WithContext("--expression-scale");
}

Result<eval::EvalResult> RunEval(const EvalAppOptions& o, const Executor& executor, std::ostream& out,
                                 std::ostream& err) {
  ICEF_RETURN_IF_ERROR(o.Validate());
  ICEF_ASSIGN_OR_RETURN(const Dataset dataset, LoadDataset(o.dataset));
  ICEF_ASSIGN_OR_RETURN(const TrainedModel loaded, LoadTrainedModel(o.model, executor, o.overrides));
  ICEF_ASSIGN_OR_RETURN(const std::optional<eval::LpipsNet> lpips,
                        eval::LoadLpipsIfConfigured(o.lpips_weights));
  eval::FaceIdentityOptions fo;
  fo.model_dir = o.faceid_model.string();
  Result<eval::FaceIdentity> identity = eval::FaceIdentity::Load(fo);
  eval::EvalNetworks networks;
  std::optional<eval::FaceIdentity> identity_holder;
  if (identity.ok()) {
    identity_holder = std::move(identity).value();
    networks.identity = &*identity_holder;
  } else {
    // An explicitly named model must load; the default one may be missing (identity is then null).
    if (!o.faceid_model.empty()) return identity.status();
    networks.identity_note = identity.status().message();
    err << "icef eval: warning: identity metrics unavailable: " << networks.identity_note << "\n";
  }
  if (lpips) networks.lpips = &*lpips;
  const eval::EvalOptions options = MakeEvalOptions(o);
  ProgressBar progress("eval", static_cast<int64_t>(dataset.test.size()), out, o.interactive);
  ICEF_ASSIGN_OR_RETURN(eval::EvalResult result,
                        eval::EvaluateModel(*loaded.model, dataset, options, networks, executor, &progress));
  const std::filesystem::path metrics = o.out / "metrics.json";
  ICEF_RETURN_IF_ERROR(eval::WriteMetricsFile(metrics, result));
  out << "method " << result.method << ", " << result.frames.size() << " test frames\n"
      << result.Table() << "wrote " << metrics.string() << " and " << (o.out / "renders").string() << "/\n";
  return result;
}

}  // namespace icef
