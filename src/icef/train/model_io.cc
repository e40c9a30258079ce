#include "icef/train/model_io.h"

#include <sstream>

#include "icef/io/checkpoint.h"

namespace icef {

namespace fs = std::filesystem;

Status SaveCheckpoint(const fs::path& path, const RunConfig& config, const AvatarModel& model,
                      const nn::Adam* adam, const TrainerState& state) {
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
  TrainerState state;
  ICEF_ASSIGN_OR_RETURN(state.step, ParseCheckpointStep(trainer_text, config_text, origin));
  ICEF_ASSIGN_OR_RETURN(const Json json, ParseJson(trainer_text, origin + " [trainer]"));
  ICEF_ASSIGN_OR_RETURN(const JsonObjectView tv, JsonObjectView::Make(json, origin, "trainer"));
  ICEF_ASSIGN_OR_RETURN(state.elapsed_seconds, tv.Number("elapsed_seconds"));
  if (state.elapsed_seconds < 0)
    return tv.Error("elapsed_seconds", "must be >= 0, got " + json["elapsed_seconds"].dump());
  if (tv.Has("skipped_steps")) {
    ICEF_ASSIGN_OR_RETURN(state.skipped_steps, tv.Int64("skipped_steps", 0, state.step));
  }
  return state;
}

Result<LoadedModel> LoadModel(const fs::path& given, const Executor& executor) {
  ICEF_ASSIGN_OR_RETURN(const fs::path path, ResolveCheckpointPath(given));
  ICEF_ASSIGN_OR_RETURN(const Checkpoint ckpt, Checkpoint::Read(path));
  const std::string origin = path.string();
  LoadedModel out;
  ICEF_ASSIGN_OR_RETURN(const std::string config_text, ckpt.Section("config"));
  ICEF_ASSIGN_OR_RETURN(const std::string trainer_text, ckpt.Section("trainer"));
  ICEF_ASSIGN_OR_RETURN(out.state, ParseTrainerSection(trainer_text, config_text, origin));
  ICEF_ASSIGN_OR_RETURN(const Json config_json, ParseJson(config_text, origin + " [config]"));
  ICEF_ASSIGN_OR_RETURN(out.config,
                        RunConfig::FromJson(config_json, origin + " [config]", ConfigSchema::OldKeys::kRead));
  // The model, as inference loads it (with the coarse-to-fine state of out.state.step).
  ICEF_ASSIGN_OR_RETURN(TrainedModel trained, LoadTrainedModel(ckpt, origin, executor));
  out.model = std::move(trained.model);
  if (ckpt.Has("adam")) {
    ICEF_ASSIGN_OR_RETURN(out.adam_state, ckpt.Section("adam"));
  }
  if (ckpt.Has("log")) {
    ICEF_ASSIGN_OR_RETURN(const std::string log, ckpt.Section("log"));
    std::istringstream in(log);
    for (std::string line; std::getline(in, line);)
      if (!line.empty()) out.state.log.push_back(line);
  }
  return out;
}

}  // namespace icef
