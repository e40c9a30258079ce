// LoadTrainedModel: a trained model for inference from a checkpoint container written here section
// by section (as train/model_io.cc's SaveCheckpoint writes it). Damaged files are refused with an
// error naming the file; inference-only keys may be overridden, the rest are refused.
#include "icef/model/trained_model.h"

#include <gtest/gtest.h>

#include <cstring>
#include <sstream>

#include "icef/io/atomic_file.h"
#include "icef/io/checkpoint.h"
#include "icef/model/model_test_util.h"
#include "icef/testing/tiny_dataset.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

// A model with deterministic, non-zero parameters (the tiny config).
std::unique_ptr<AvatarModel> TinyModel(const ModelConfig& config) {
  auto model = AvatarModel::Create(config, testing_model::TinySetup(), Executor(1));
  ICEF_CHECK(model.ok(), model.status().message());
  return std::move(model).value();
}

std::string Params(const AvatarModel& model) {
  std::ostringstream os;
  ICEF_CHECK(model.store().Write(os).ok());
  return os.str();
}

// Writes dir/checkpoint.icef of `model` after `step` steps with the given coarse-to-fine schedule;
// its config's model block is `model_json` when given (default: the model's config as written now).
fs::path WriteCheckpoint(const fs::path& dir, const AvatarModel& model, int64_t step, int anneal_steps,
                         const Json& model_json = Json()) {
  Json config;
  config["model"] = model_json.is_null() ? WriteConfig(model.config()) : model_json;
  config["train"] = {{"steps", 10}, {"anneal_steps", anneal_steps}, {"grid_anneal_steps", 0}};
  const std::string config_text = config.dump();
  CheckpointWriter w;
  w.Add("config", config_text);
  w.Add("setup", model.setup().ToJson().dump());
  w.Add("params", Params(model));
  const std::vector<float>& occ = model.occupancy().densities();
  w.Add("occupancy", std::string(reinterpret_cast<const char*>(occ.data()), occ.size() * sizeof(float)));
  const std::vector<uint8_t>& allowed = model.occupancy().allowed();
  w.Add("occupancy_allowed", std::string(allowed.begin(), allowed.end()));
  w.Add("trainer",
        Json{{"step", step}, {"elapsed_seconds", 1.0}, {"config_hash", Fnv1a64(config_text)}}.dump());
  const fs::path path = dir / kCheckpointFile;
  ICEF_CHECK(w.WriteAtomic(path).ok());
  return path;
}

fs::path WriteTinyCheckpoint(const std::string& name, int64_t step = 4, int anneal_steps = 8) {
  const auto model = TinyModel(testing_model::TinyModelConfig("icef"));
  return WriteCheckpoint(testing::MakeTempDir(name), *model, step, anneal_steps);
}

// Rewrites the container without section `drop`.
void DropSection(const fs::path& path, const std::string& drop) {
  const Checkpoint ckpt = Checkpoint::Read(path).value();
  CheckpointWriter w;
  for (const std::string& n : ckpt.SectionNames())
    if (n != drop) w.Add(n, ckpt.Section(n).value());
  ASSERT_TRUE(w.WriteAtomic(path).ok());
}

void ExpectErrorNaming(const Status& s, const fs::path& path, const std::string& what) {
  ASSERT_FALSE(s.ok()) << "expected an error about " << what;
  EXPECT_NE(s.message().find(path.string()), std::string::npos) << s.message();
  EXPECT_NE(s.message().find(what), std::string::npos) << s.message();
}

// Checkpoints written before the model config had one block per component store flat keys; they
// still load, into the same config and parameters.
TEST(TrainedModel, LoadsCheckpointsWithTheFlatKeysOfEarlierVersions) {
  const ModelConfig config = testing_model::TinyModelConfig("icef");
  const auto model = TinyModel(config);
  const Json flat = Json::parse(R"({"method": "icef", "grid_levels": 4, "grid_log2_table_size": 10,
      "grid_base_resolution": 4.0, "grid_finest_resolution": 32.0, "density_hidden": 16, "geo_features": 8,
      "color_hidden": [16], "deform_hidden": [16, 16], "deform_frequencies": 3, "samples_per_ray": 16,
      "occupancy_resolution": 16, "visual_hull": true, "render_supersample": 1, "transmittance_eps": 0.0001})");
  const fs::path path = WriteCheckpoint(testing::MakeTempDir("flat_keys"), *model, 4, 8, flat);
  auto loaded = LoadTrainedModel(path, Executor(1));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_EQ(WriteConfig(loaded->config), WriteConfig(config));
  EXPECT_EQ(Params(*loaded->model), Params(*model));
}

TEST(TrainedModel, LoadsParametersConfigAndScheduleFromAFileOrItsDirectory) {
  const ModelConfig config = testing_model::TinyModelConfig("icef");
  const auto saved = TinyModel(config);
  const fs::path path = WriteCheckpoint(testing::MakeTempDir("trained_model_load"), *saved, 4, 8);
  for (const fs::path& given : {path, path.parent_path()}) {
    Result<TrainedModel> loaded = LoadTrainedModel(given, Executor(1));
    ASSERT_TRUE(loaded.ok()) << loaded.status().message();
    EXPECT_EQ(loaded->step, 4);
    EXPECT_EQ(WriteConfig(loaded->config), WriteConfig(config));
    EXPECT_EQ(Params(*loaded->model), Params(*saved));
    EXPECT_EQ(loaded->model->occupancy().densities(), saved->occupancy().densities());
    // Half way through an 8-step anneal of 3 frequencies.
    ASSERT_NE(loaded->model->residual_field(), nullptr);
    EXPECT_DOUBLE_EQ(loaded->model->residual_field()->annealing(), 1.5);
  }
}

TEST(TrainedModel, MissingCheckpointIsAClearError) {
  const fs::path dir = testing::MakeTempDir("trained_model_missing");
  ExpectErrorNaming(LoadTrainedModel(dir, Executor(1)).status(), dir / kCheckpointFile, "no checkpoint here");
}

TEST(TrainedModel, CorruptFileIsRefusedNamingIt) {
  const fs::path path = WriteTinyCheckpoint("trained_model_corrupt");
  std::string bytes = ReadFile(path).value();
  bytes[bytes.size() / 2] ^= 0x40;
  ASSERT_TRUE(WriteFileAtomic(path, bytes).ok());
  ExpectErrorNaming(LoadTrainedModel(path, Executor(1)).status(), path, "checksum mismatch");
  // Truncated.
  ASSERT_TRUE(WriteFileAtomic(path, bytes.substr(0, 10)).ok());
  ExpectErrorNaming(LoadTrainedModel(path, Executor(1)).status(), path, "not a valid ICEF checkpoint");
}

TEST(TrainedModel, OtherFormatVersionIsRefusedNamingIt) {
  const fs::path path = WriteTinyCheckpoint("trained_model_version");
  std::string bytes = ReadFile(path).value();
  const uint32_t version = kCheckpointFormatVersion + 1;
  std::memcpy(bytes.data() + 8, &version, sizeof version);  // after the 8-byte magic
  const uint64_t checksum = Fnv1a64(std::string_view(bytes.data(), bytes.size() - 8));
  std::memcpy(bytes.data() + bytes.size() - 8, &checksum, sizeof checksum);
  ASSERT_TRUE(WriteFileAtomic(path, bytes).ok());
  ExpectErrorNaming(LoadTrainedModel(path, Executor(1)).status(), path,
                    "format version " + std::to_string(version));
}

TEST(TrainedModel, MissingSectionIsRefusedNamingFileAndSection) {
  for (const std::string section :
       {"config", "trainer", "setup", "params", "occupancy", "occupancy_allowed"}) {
    const fs::path path = WriteTinyCheckpoint("trained_model_section");
    DropSection(path, section);
    ExpectErrorNaming(LoadTrainedModel(path, Executor(1)).status(), path, "no section '" + section + "'");
  }
}

TEST(TrainedModel, BadModelBlockAndTrainerFieldsNameTheField) {
  const ModelConfig config = testing_model::TinyModelConfig("icef");
  const auto model = TinyModel(config);
  const fs::path path = WriteCheckpoint(testing::MakeTempDir("trained_model_fields"), *model, 3, 0);
  const Checkpoint ckpt = Checkpoint::Read(path).value();
  // An unknown model key (the hash resealed to match, so only the config check stands).
  Json bad = Json::parse(ckpt.Section("config").value());
  bad["model"]["grid_levelz"] = 4;
  CheckpointWriter w;
  for (const std::string& n : ckpt.SectionNames()) {
    if (n == "config")
      w.Add(n, bad.dump());
    else if (n == "trainer")
      w.Add(n, Json{{"step", 3}, {"config_hash", Fnv1a64(bad.dump())}}.dump());
    else
      w.Add(n, ckpt.Section(n).value());
  }
  ASSERT_TRUE(w.WriteAtomic(path).ok());
  ExpectErrorNaming(LoadTrainedModel(path, Executor(1)).status(), path, "model.grid_levelz: unknown key");
  // The edited config beside the original trainer section, whose hash is of the original config.
  CheckpointWriter w2;
  for (const std::string& n : ckpt.SectionNames())
    w2.Add(n, n == "config" ? bad.dump() : ckpt.Section(n).value());
  ASSERT_TRUE(w2.WriteAtomic(path).ok());
  ExpectErrorNaming(LoadTrainedModel(path, Executor(1)).status(), path,
                    "trainer.config_hash: does not match");
}

TEST(TrainedModel, InferenceOverridesChangeTheLoadedConfig) {
  const fs::path path = WriteTinyCheckpoint("trained_model_override");
  Result<TrainedModel> loaded = LoadTrainedModel(
      path, Executor(1),
      {"model.render.supersample=3", "model.render.transmittance_eps=0.001", "model.bf16_inference=false",
       "model.sampler.num_samples=24", "model.render.sample_factor=1"});
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_EQ(loaded->config.render.supersample, 3);
  EXPECT_EQ(loaded->config.render.transmittance_eps, 0.001);
  EXPECT_FALSE(loaded->config.bf16_inference);
  EXPECT_EQ(loaded->config.sampler.num_samples, 24);
  EXPECT_EQ(loaded->config.render.sample_factor, 1);
  EXPECT_EQ(loaded->model->config().render.supersample, 3);  // the model is built from it
  EXPECT_EQ(loaded->model->config().sampler.num_samples, 24);
  EXPECT_EQ(loaded->config.static_field.grid.num_levels,
            testing_model::TinyModelConfig("icef").static_field.grid.num_levels);
}

TEST(TrainedModel, ArchitectureKeysAreRefusedNamingTheKey) {
  ModelConfig config;
  for (const std::string key :
       {"model.static_field.grid.num_levels=8", "model.static_field.density_hidden=32", "model.method=warp",
        "model.static_field.color_hidden=[8]", "train.steps=5", "model.no_such_key=1"}) {
    const Status s = ApplyInferenceOverride(key, &config);
    ASSERT_FALSE(s.ok()) << key << " was accepted";
    const std::string name = key.substr(0, key.find('='));
    EXPECT_NE(s.message().find(name + " cannot be changed on a trained model"), std::string::npos)
        << s.message();
    EXPECT_NE(s.message().find("model.render.supersample"), std::string::npos) << s.message();
    EXPECT_EQ(s.message().find('\n'), std::string::npos) << "one line: " << s.message();
  }
  EXPECT_EQ(WriteConfig(config), WriteConfig(ModelConfig{}));  // nothing changed
  // A load with a refused key fails before building anything.
  const fs::path path = WriteTinyCheckpoint("trained_model_refuse");
  const Status renamed = LoadTrainedModel(path, Executor(1), {"model.render_supersample=2"}).status();
  EXPECT_NE(
      renamed.message().find("model.render_supersample cannot be changed on a trained model (renamed to "
                             "model.render.supersample)"),
      std::string::npos)
      << renamed.message();
  const Status s = LoadTrainedModel(path, Executor(1), {"model.static_field.grid.num_levels=8"}).status();
  EXPECT_NE(s.message().find("model.static_field.grid.num_levels cannot be changed"), std::string::npos)
      << s.message();
}

TEST(TrainedModel, OverrideValuesAreParsedAndValidatedAsForTrain) {
  ModelConfig config;
  Status s = ApplyInferenceOverride("model.render.supersample=99", &config);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("--set model.render.supersample=99: render.supersample must be in 1..8"),
            std::string::npos)
      << s.message();
  s = ApplyInferenceOverride("model.render.supersample=two", &config);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("model.render.supersample: expected a number"), std::string::npos)
      << s.message();
  s = ApplyInferenceOverride("render_supersample", &config);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("expected SECTION.KEY=VALUE"), std::string::npos) << s.message();
  EXPECT_EQ(WriteConfig(config), WriteConfig(ModelConfig{}));
}

}  // namespace
}  // namespace icef
