#include "icef/model/trained_model.h"

#include <algorithm>
#include <climits>
#include <cstring>
#include <sstream>

#include "icef/io/config_override.h"
#include "icef/model/coarse_to_fine.h"

namespace icef {

namespace fs = std::filesystem;

Result<fs::path> ResolveCheckpointPath(const fs::path& given) {
  std::error_code ec;
  const fs::path path = fs::is_directory(given, ec) ? given / kCheckpointFile : given;
  if (!fs::exists(path, ec))
    return Status::Error(path.string() + ": no checkpoint here (train a model with `icef train` first)");
  return path;
}

Result<int64_t> ParseCheckpointStep(const std::string& trainer_text, const std::string& config_text,
                                    const std::string& origin) {
  ICEF_ASSIGN_OR_RETURN(const Json json, ParseJson(trainer_text, origin + " [trainer]"));
  ICEF_ASSIGN_OR_RETURN(const JsonObjectView tv, JsonObjectView::Make(json, origin, "trainer"));
  ICEF_ASSIGN_OR_RETURN(const int64_t step, tv.Int64("step", 0, kMaxCheckpointStep));
  // The hash covers the config section exactly as written, so a checkpoint whose config was
  // edited (or whose sections come from different runs) is refused.
  ICEF_ASSIGN_OR_RETURN(const uint64_t stored_hash, tv.Uint64("config_hash"));
  if (stored_hash != Fnv1a64(config_text))
    return tv.Error("config_hash",
                    "does not match the checkpoint's config section (the config or the trainer state "
                    "was altered after the checkpoint was written)");
  return step;
}

const std::vector<std::string>& InferenceModelKeys() {
  static const std::vector<std::string> keys = {"render.supersample", "render.sample_factor",
                                                "sampler.num_samples", "render.transmittance_eps",
                                                "bf16_inference"};
  return keys;
}

Status ApplyInferenceOverride(const std::string& assignment, ModelConfig* config) {
  ICEF_ASSIGN_OR_RETURN(const ConfigOverride o, ParseConfigOverride(assignment));
  const std::string origin = "--set " + assignment;
  const Json patch = o.SectionPatch();
  ICEF_ASSIGN_OR_RETURN(const JsonObjectView view, JsonObjectView::Make(patch, origin, "model"));
  ModelConfig updated = *config;
  const std::vector<std::string>& allowed = InferenceModelKeys();
  if (o.section != "model" || std::find(allowed.begin(), allowed.end(), o.key) == allowed.end()) {
    std::string why = "not a model key";
    if (o.section == "model") {
      ConfigSchema schema;
      updated.Bind(schema);
      const std::vector<std::string> keys = schema.Keys();
      const std::string renamed = schema.RenamedTo(o.key);
      why = std::find(keys.begin(), keys.end(), o.key) != keys.end() ? "fixed when the model was trained"
            : renamed.empty()                                        ? "no such model key"
                                                                     : "renamed to model." + renamed;
    }
    std::string can;
    for (const std::string& k : allowed) can += (can.empty() ? "model." : ", model.") + k;
    return Status::Error(origin + ": " + o.section + "." + o.key + " cannot be changed on a trained model (" +
                         why + "); only " + can + " can");
  }
  ICEF_RETURN_IF_ERROR(ReadConfig(view, &updated));
  ICEF_RETURN_IF_ERROR(updated.Validate().WithContext(origin));
  *config = updated;
  return Status::Ok();
}

namespace {

// The coarse-to-fine schedule lengths of the stored run config's "train" block (the only training
// keys inference needs; absent keys have their defaults).
struct Schedule {
  int anneal_steps = kDefaultAnnealSteps;
  int grid_anneal_steps = kDefaultGridAnnealSteps;
};

Result<Schedule> ReadSchedule(const JsonObjectView& root) {
  Schedule s;
  if (!root.Has("train")) return s;
  ICEF_ASSIGN_OR_RETURN(const JsonObjectView t, root.Object("train"));
  if (t.Has("anneal_steps")) {
    ICEF_ASSIGN_OR_RETURN(const int64_t v, t.Int64("anneal_steps", 0, INT_MAX));
    s.anneal_steps = static_cast<int>(v);
  }
  if (t.Has("grid_anneal_steps")) {
    ICEF_ASSIGN_OR_RETURN(const int64_t v, t.Int64("grid_anneal_steps", 0, INT_MAX));
    s.grid_anneal_steps = static_cast<int>(v);
  }
  return s;
}

}  // namespace

Result<TrainedModel> LoadTrainedModel(const Checkpoint& ckpt, const std::string& origin,
                                      const Executor& executor, const std::vector<std::string>& overrides) {
  TrainedModel out;
  ICEF_ASSIGN_OR_RETURN(const std::string config_text, ckpt.Section("config"));
  ICEF_ASSIGN_OR_RETURN(const std::string trainer_text, ckpt.Section("trainer"));
  ICEF_ASSIGN_OR_RETURN(out.step, ParseCheckpointStep(trainer_text, config_text, origin));
  // The model block of the run config, read as RunConfig::FromJson reads it (same errors).
  const std::string config_origin = origin + " [config]";
  ICEF_ASSIGN_OR_RETURN(const Json config_json, ParseJson(config_text, config_origin));
  ICEF_ASSIGN_OR_RETURN(const JsonObjectView root, JsonObjectView::Make(config_json, config_origin, ""));
  if (root.Has("model")) {
    ICEF_ASSIGN_OR_RETURN(const JsonObjectView m, root.Object("model"));
    ICEF_RETURN_IF_ERROR(ReadConfig(m, &out.config, ConfigSchema::OldKeys::kRead));
  }
  ICEF_RETURN_IF_ERROR(out.config.Validate().WithContext("model").WithContext(config_origin));
  ICEF_ASSIGN_OR_RETURN(const Schedule schedule, ReadSchedule(root));
  for (const std::string& assignment : overrides)
    ICEF_RETURN_IF_ERROR(ApplyInferenceOverride(assignment, &out.config));

  ICEF_ASSIGN_OR_RETURN(const std::string setup_text, ckpt.Section("setup"));
  ICEF_ASSIGN_OR_RETURN(const Json setup_json, ParseJson(setup_text, origin + " [setup]"));
  ICEF_ASSIGN_OR_RETURN(const ModelSetup setup, ModelSetup::FromJson(setup_json, origin + " [setup]"));
  ICEF_ASSIGN_OR_RETURN(out.model, AvatarModel::Create(out.config, setup, executor));
  ICEF_ASSIGN_OR_RETURN(const std::string params, ckpt.Section("params"));
  std::istringstream params_in(params);
  ICEF_RETURN_IF_ERROR(out.model->store().Read(params_in).WithContext(origin + " [params]"));
  ICEF_ASSIGN_OR_RETURN(std::string occ, ckpt.Section("occupancy"));
  if (occ.size() % sizeof(float) != 0)
    return Status::Error(origin + " [occupancy]: size is not a whole number of floats");
  std::vector<float> densities(occ.size() / sizeof(float));
  if (!occ.empty()) std::memcpy(densities.data(), occ.data(), occ.size());  // never memcpy(nullptr, ...)
  ICEF_RETURN_IF_ERROR(
      out.model->occupancy().SetDensities(std::move(densities)).WithContext(origin + " [occupancy]"));
  ICEF_ASSIGN_OR_RETURN(const std::string allowed, ckpt.Section("occupancy_allowed"));
  ICEF_RETURN_IF_ERROR(out.model->occupancy()
                           .SetAllowed(std::vector<uint8_t>(allowed.begin(), allowed.end()))
                           .WithContext(origin + " [occupancy_allowed]"));
  // The coarse-to-fine state the model was trained to at this step.
  if (DeformationField* d = out.model->residual_field())
    d->SetAnnealing(DeformationAnnealing(out.config, schedule.anneal_steps, out.step));
  out.model->static_field().SetLevelWeights(
      GridLevelWeights(out.config, schedule.grid_anneal_steps, out.step));
  return out;
}

Result<TrainedModel> LoadTrainedModel(const fs::path& given, const Executor& executor,
                                      const std::vector<std::string>& overrides) {
  ICEF_ASSIGN_OR_RETURN(const fs::path path, ResolveCheckpointPath(given));
  ICEF_ASSIGN_OR_RETURN(const Checkpoint ckpt, Checkpoint::Read(path));
  return LoadTrainedModel(ckpt, path.string(), executor, overrides);
}

}  // namespace icef
