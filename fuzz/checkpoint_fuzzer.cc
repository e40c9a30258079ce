// libFuzzer target: the checkpoint reader. Each input is tried twice:
//  1. as is, through Checkpoint::Parse (magic, version, checksum, section table);
//  2. resealed: the input minus its last 8 bytes, followed by the correct FNV-1a checksum of it,
//     so that mutations get past the checksum and reach the section table and the sections.
// Whenever a container parses, its sections go through the same parsing steps as LoadModel
// (train/model_io.cc), in the same order: trainer section -> ParseTrainerSection (step range,
// config hash), config JSON -> RunConfig (strict) -> Validate, setup JSON -> ModelSetup, params ->
// ParameterStore::Read, occupancy -> OccupancyGrid::SetDensities, occupancy_allowed ->
// OccupancyGrid::SetAllowed, log lines. Parameters and occupancy are read into one tiny AvatarModel built
// once (a model built from a fuzzed config could legitimately need gigabytes). Keep this in step with
// LoadModel. Errors are fine; crashes, leaks and undefined behaviour are not.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "icef/io/checkpoint.h"
#include "icef/io/json_util.h"
#include "icef/model/avatar_model.h"
#include "icef/model/model_test_util.h"
#include "icef/train/model_io.h"
#include "icef/train/train_config.h"

namespace {

const icef::Executor& FuzzExecutor() {
  static const icef::Executor executor(1);
  return executor;
}

icef::AvatarModel& TinyModel() {
  static std::unique_ptr<icef::AvatarModel> model = [] {
    icef::Result<std::unique_ptr<icef::AvatarModel>> m = icef::AvatarModel::Create(
        icef::testing_model::TinyModelConfig("icef"), icef::testing_model::TinySetup(), FuzzExecutor());
    if (!m.ok()) std::abort();
    return std::move(m).value();
  }();
  return *model;
}

// LoadModel's section parsing; returns at the first error, as LoadModel does.
icef::Status ParseSections(const icef::Checkpoint& ckpt) {
  const std::string origin = "fuzz.icef";
  ICEF_ASSIGN_OR_RETURN(const std::string config_text, ckpt.Section("config"));
  // Unlike LoadModel, go on after a trainer-section error: a mutated config no longer matches
  // the stored config_hash, and the config parser below should still see it.
  if (ckpt.Has("trainer")) {
    ICEF_ASSIGN_OR_RETURN(const std::string trainer_text, ckpt.Section("trainer"));
    const icef::Result<icef::TrainerState> state =
        icef::ParseTrainerSection(trainer_text, config_text, origin);
    if (state.ok() &&
        (state->step < 0 || state->step > icef::kMaxCheckpointStep || state->skipped_steps < 0 ||
         state->skipped_steps > state->step || !(state->elapsed_seconds >= 0)))
      std::abort();  // ParseTrainerSection let an out-of-range value through
    if (!state.ok() && state.status().message().find(origin) == std::string::npos) std::abort();
  }
  ICEF_ASSIGN_OR_RETURN(const icef::Json config_json, icef::ParseJson(config_text, origin + " [config]"));
  ICEF_ASSIGN_OR_RETURN(const icef::RunConfig config,
                        icef::RunConfig::FromJson(config_json, origin + " [config]"));
  (void)config.Validate();
  (void)config.Hash();
  ICEF_ASSIGN_OR_RETURN(const std::string setup_text, ckpt.Section("setup"));
  ICEF_ASSIGN_OR_RETURN(const icef::Json setup_json, icef::ParseJson(setup_text, origin + " [setup]"));
  ICEF_ASSIGN_OR_RETURN(const icef::ModelSetup setup,
                        icef::ModelSetup::FromJson(setup_json, origin + " [setup]"));
  (void)setup.ExpressionIndex("jaw_open");
  icef::AvatarModel& model = TinyModel();
  ICEF_ASSIGN_OR_RETURN(const std::string params, ckpt.Section("params"));
  std::istringstream params_in(params);
  ICEF_RETURN_IF_ERROR(model.store().Read(params_in));
  ICEF_ASSIGN_OR_RETURN(std::string occ, ckpt.Section("occupancy"));
  if (occ.size() % sizeof(float) != 0) return icef::Status::Error("occupancy: not whole floats");
  std::vector<float> densities(occ.size() / sizeof(float));
  if (!occ.empty()) std::memcpy(densities.data(), occ.data(), occ.size());
  ICEF_RETURN_IF_ERROR(model.occupancy().SetDensities(std::move(densities)));
  ICEF_ASSIGN_OR_RETURN(const std::string allowed, ckpt.Section("occupancy_allowed"));
  ICEF_RETURN_IF_ERROR(model.occupancy().SetAllowed(std::vector<uint8_t>(allowed.begin(), allowed.end())));
  if (ckpt.Has("log")) {
    ICEF_ASSIGN_OR_RETURN(const std::string log, ckpt.Section("log"));
    (void)log;
  }
  return icef::Status::Ok();
}

void TryParse(std::string bytes) {
  icef::Result<icef::Checkpoint> ckpt = icef::Checkpoint::Parse(std::move(bytes), "fuzz.icef");
  if (!ckpt.ok()) {
    if (ckpt.status().message().find("fuzz.icef") == std::string::npos) std::abort();  // must name the origin
    return;
  }
  (void)ckpt->SectionNames();
  (void)ParseSections(*ckpt);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  TryParse(bytes);
  if (size >= 8) {
    bytes.resize(size - 8);
    const uint64_t sum = icef::Fnv1a64(bytes);
    char tail[8];
    std::memcpy(tail, &sum, 8);
    bytes.append(tail, 8);
    TryParse(std::move(bytes));
  }
  return 0;
}
