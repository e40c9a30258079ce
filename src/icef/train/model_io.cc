#include "icef/train/model_io.h"

#include <cstring>
#include <sstream>

#include "icef/io/checkpoint.h"

namespace icef {

namespace fs = std::filesystem;

Status SaveCheckpoint(const fs::path& path, const RunConfig& config, const AvatarModel& model, const nn::Adam* adam,
                      const TrainerState& state) {
  CheckpointWriter w;
  const std::string config_text = config.ToJson().dump();
  w.Add("config", config_text);
  w.Add("setup", model.setup().ToJson().dump());
  std::ostringstream params;
  ICEF_RETURN_IF_ERROR(model.store().Write(params));
  w.Add("params", params.str());
  if (adam) {
    std::ostringstream a;
    ICEF_RETURN_IF_ERROR(adam->Write(a));
    w.Add("adam", a.str());
  }
  const std::vector<float>& occ = model.occupancy().densities();
  w.Add("occupancy", std::string(reinterpret_cast<const char*>(occ.data()), occ.size() * sizeof(float)));
  const std::vector<uint8_t>& allowed = model.occupancy().allowed();
  w.Add("occupancy_allowed", std::string(allowed.begin(), allowed.end()));
  Json trainer;
  trainer["step"] = state.step;
  trainer["elapsed_seconds"] = state.elapsed_seconds;
  trainer["skipped_steps"] = state.skipped_steps;
  trainer["config_hash"] = Fnv1a64(config_text);  // = config.Hash()
  w.Add("trainer", trainer.dump());
  std::string log;
  for (const auto& line : state.log) log += line + "\n";
  w.Add("log", log);
  return w.WriteAtomic(path);
}

Result<TrainerState> ParseTrainerSection(const std::string& trainer_text, const std::string& config_text,
                                         const std::string& origin) {
  ICEF_ASSIGN_OR_RETURN(const Json json, ParseJson(trainer_text, origin + " [trainer]"));
  ICEF_ASSIGN_OR_RETURN(const JsonObjectView tv, JsonObjectView::Make(json, origin, "trainer"));
  TrainerState state;
  ICEF_ASSIGN_OR_RETURN(state.step, tv.Int64("step", 0, kMaxCheckpointStep));
  ICEF_ASSIGN_OR_RETURN(state.elapsed_seconds, tv.Number("elapsed_seconds"));
  if (state.elapsed_seconds < 0) return tv.Error("elapsed_seconds", "must be >= 0, got " + json["elapsed_seconds"].dump());
  if (tv.Has("skipped_steps")) {
    ICEF_ASSIGN_OR_RETURN(state.skipped_steps, tv.Int64("skipped_steps", 0, state.step));
  }
  // The hash covers the config section exactly as written, so a checkpoint whose config was
  // edited (or whose sections come from different runs) is refused.
  ICEF_ASSIGN_OR_RETURN(const uint64_t stored_hash, tv.Uint64("config_hash"));
  if (stored_hash != Fnv1a64(config_text))
    return tv.Error("config_hash", "does not match the checkpoint's config section (the config or the trainer state "
                                   "was altered after the checkpoint was written)");
  return state;
}

Result<LoadedModel> LoadModel(const fs::path& given, const Executor& executor) {
  std::error_code ec;
  const fs::path path = fs::is_directory(given, ec) ? given / kCheckpointFile : given;
  if (!fs::exists(path, ec))
    return Status::Error(path.string() + ": no checkpoint here (train a model with `icef train` first)");
  ICEF_ASSIGN_OR_RETURN(const Checkpoint ckpt, Checkpoint::Read(path));
  const std::string origin = path.string();
  LoadedModel out;
  ICEF_ASSIGN_OR_RETURN(const std::string config_text, ckpt.Section("config"));
  ICEF_ASSIGN_OR_RETURN(const std::string trainer_text, ckpt.Section("trainer"));
  ICEF_ASSIGN_OR_RETURN(out.state, ParseTrainerSection(trainer_text, config_text, origin));
  ICEF_ASSIGN_OR_RETURN(const Json config_json, ParseJson(config_text, origin + " [config]"));
  ICEF_ASSIGN_OR_RETURN(out.config, RunConfig::FromJson(config_json, origin + " [config]"));
  ICEF_ASSIGN_OR_RETURN(const std::string setup_text, ckpt.Section("setup"));
  ICEF_ASSIGN_OR_RETURN(const Json setup_json, ParseJson(setup_text, origin + " [setup]"));
  ICEF_ASSIGN_OR_RETURN(const ModelSetup setup, ModelSetup::FromJson(setup_json, origin + " [setup]"));
  ICEF_ASSIGN_OR_RETURN(out.model, AvatarModel::Create(out.config.model, setup, executor));
  ICEF_ASSIGN_OR_RETURN(const std::string params, ckpt.Section("params"));
  std::istringstream params_in(params);
  ICEF_RETURN_IF_ERROR(out.model->store().Read(params_in).WithContext(origin + " [params]"));
  ICEF_ASSIGN_OR_RETURN(std::string occ, ckpt.Section("occupancy"));
  if (occ.size() % sizeof(float) != 0) return Status::Error(origin + " [occupancy]: size is not a whole number of floats");
  std::vector<float> densities(occ.size() / sizeof(float));
  if (!occ.empty()) std::memcpy(densities.data(), occ.data(), occ.size());  // never memcpy(nullptr, ...)
  ICEF_RETURN_IF_ERROR(out.model->occupancy().SetDensities(std::move(densities)).WithContext(origin + " [occupancy]"));
  ICEF_ASSIGN_OR_RETURN(const std::string allowed, ckpt.Section("occupancy_allowed"));
  ICEF_RETURN_IF_ERROR(out.model->occupancy()
                           .SetAllowed(std::vector<uint8_t>(allowed.begin(), allowed.end()))
                           .WithContext(origin + " [occupancy_allowed]"));
  if (ckpt.Has("adam")) {
    ICEF_ASSIGN_OR_RETURN(out.adam_state, ckpt.Section("adam"));
  }
  if (DeformationField* d = out.model->residual_field()) d->SetAnnealing(DeformationAnnealing(out.config, out.state.step));
  out.model->static_field().SetLevelWeights(GridLevelWeights(out.config, out.state.step));
  if (ckpt.Has("log")) {
    ICEF_ASSIGN_OR_RETURN(const std::string log, ckpt.Section("log"));
    std::istringstream in(log);
    for (std::string line; std::getline(in, line);)
      if (!line.empty()) out.state.log.push_back(line);
  }
  return out;
}

}  // namespace icef
