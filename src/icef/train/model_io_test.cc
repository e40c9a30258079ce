// LoadModel's checks of the checkpoint's trainer section (issue 7): the step must be a whole
// number in range, and the stored config_hash must match the config stored beside it. Each case
// rewrites one section of a valid checkpoint and reseals the container, so the container checksum
// passes and only these checks stand between the damage and a loaded model.
#include "icef/train/model_io.h"

#include <gtest/gtest.h>

#include "icef/io/checkpoint.h"
#include "icef/model/model_test_util.h"
#include "icef/testing/tiny_dataset.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

// A checkpoint of the tiny model after `step` steps; returns its path.
fs::path WriteTinyCheckpoint(const fs::path& dir, int64_t step) {
  const Executor executor(1);
  RunConfig config;
  config.model = testing_model::TinyModelConfig("icef");
  config.train.steps = 10;
  auto model = AvatarModel::Create(config.model, testing_model::TinySetup(), executor);
  ICEF_CHECK(model.ok(), model.status().message());
  TrainerState state;
  state.step = step;
  state.elapsed_seconds = 1.5;
  const fs::path path = dir / kCheckpointFile;
  ICEF_CHECK(SaveCheckpoint(path, config, **model, nullptr, state).ok());
  return path;
}

// Replaces one section's bytes and writes a valid (correctly checksummed) container again.
void RewriteSection(const fs::path& path, const std::string& name, const std::string& bytes) {
  const Checkpoint ckpt = Checkpoint::Read(path).value();
  CheckpointWriter w;
  for (const std::string& n : ckpt.SectionNames()) w.Add(n, n == name ? bytes : ckpt.Section(n).value());
  ASSERT_TRUE(w.WriteAtomic(path).ok());
}

Json TrainerSection(const fs::path& path) {
  return Json::parse(Checkpoint::Read(path)->Section("trainer").value());
}

TEST(ModelIo, ValidCheckpointRoundTripsTrainerState) {
  const fs::path path = WriteTinyCheckpoint(testing::MakeTempDir("model_io_valid"), 7);
  const Result<LoadedModel> loaded = LoadModel(path, Executor(1));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_EQ(loaded->state.step, 7);
  EXPECT_EQ(loaded->state.elapsed_seconds, 1.5);
  EXPECT_EQ(loaded->state.skipped_steps, 0);
  EXPECT_EQ(TrainerSection(path)["config_hash"].get<uint64_t>(), loaded->config.Hash());
}

TEST(ModelIo, StepOutOfRangeIsRefusedNamingFileAndField) {
  const fs::path path = WriteTinyCheckpoint(testing::MakeTempDir("model_io_step"), 7);
  const Json good = TrainerSection(path);
  // Each value as JSON text, and what the error must say about it.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"-1", "got -1"},
      {"1.5", "got 1.5"},
      {"1e300", "got 1e+300"},
      {"9007199254740993", "got 9007199254740993"},
      {"\"ten\"", "expected a number, got a string"},
      {"null", "expected a number, got null"}};
  for (const auto& [value, why] : cases) {
    std::string text = good.dump();
    const std::string key = "\"step\":" + good["step"].dump();
    text.replace(text.find(key), key.size(), "\"step\":" + value);
    RewriteSection(path, "trainer", text);
    const Status s = LoadModel(path, Executor(1)).status();
    ASSERT_FALSE(s.ok()) << "step " << value << " was accepted";
    EXPECT_NE(s.message().find(path.string() + ": trainer.step: "), std::string::npos) << s.message();
    EXPECT_NE(s.message().find(why), std::string::npos) << s.message();
  }
  Json bad = good;
  bad["elapsed_seconds"] = -3.0;
  RewriteSection(path, "trainer", bad.dump());
  EXPECT_NE(LoadModel(path, Executor(1)).status().message().find("trainer.elapsed_seconds: must be >= 0"),
            std::string::npos);
  bad = good;
  bad["skipped_steps"] = 8;  // more than the 7 steps done
  RewriteSection(path, "trainer", bad.dump());
  EXPECT_NE(LoadModel(path, Executor(1))
                .status()
                .message()
                .find("trainer.skipped_steps: expected an integer in [0, 7]"),
            std::string::npos);
  bad = good;
  bad["step"] = 9007199254740992;  // 2^53: the largest accepted
  RewriteSection(path, "trainer", bad.dump());
  const Result<LoadedModel> largest = LoadModel(path, Executor(1));
  ASSERT_TRUE(largest.ok()) << largest.status().message();
  EXPECT_EQ(largest->state.step, kMaxCheckpointStep);
}

TEST(ModelIo, ConfigHashMustMatchTheStoredConfig) {
  const fs::path path = WriteTinyCheckpoint(testing::MakeTempDir("model_io_hash"), 3);
  const Json trainer = TrainerSection(path);
  // A stored hash that is off by one.
  Json bad = trainer;
  bad["config_hash"] = trainer["config_hash"].get<uint64_t>() + 1;
  RewriteSection(path, "trainer", bad.dump());
  Status s = LoadModel(path, Executor(1)).status();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find(path.string() + ": trainer.config_hash: "), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("does not match"), std::string::npos) << s.message();
  // The right hash back, but the config edited (a valid config, just not the one trained with).
  RewriteSection(path, "trainer", trainer.dump());
  ASSERT_TRUE(LoadModel(path, Executor(1)).ok());
  Json config = Json::parse(Checkpoint::Read(path)->Section("config").value());
  config["train"]["lambda_id"] = 0.5;
  RewriteSection(path, "config", config.dump());
  s = LoadModel(path, Executor(1)).status();
  ASSERT_FALSE(s.ok()) << "an edited config was loaded";
  EXPECT_NE(s.message().find("trainer.config_hash"), std::string::npos) << s.message();
  // A missing hash or one that is not an unsigned integer.
  bad = trainer;
  bad.erase("config_hash");
  RewriteSection(path, "trainer", bad.dump());
  EXPECT_NE(
      LoadModel(path, Executor(1)).status().message().find("trainer.config_hash: missing required field"),
      std::string::npos);
  bad["config_hash"] = -5;
  RewriteSection(path, "trainer", bad.dump());
  EXPECT_NE(LoadModel(path, Executor(1))
                .status()
                .message()
                .find("trainer.config_hash: expected a non-negative integer"),
            std::string::npos);
}

}  // namespace
}  // namespace icef
