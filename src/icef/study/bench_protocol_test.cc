#include "icef/study/bench_protocol.h"

#include <gtest/gtest.h>

#include <set>
#include <sstream>

#include "icef/io/atomic_file.h"
#include "icef/io/image.h"

namespace icef::eval {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("icef_bench_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(BenchProtocolTest, PlansRunsInStableOrder) {
  BenchOptions o;
  o.out_dir = "x";
  const std::vector<RunId> runs = PlanRuns(o);
  ASSERT_EQ(runs.size(), 3u * 3u * 7u);
  EXPECT_EQ(runs[0].Name(), "id1_k3_icef-prior");
  EXPECT_EQ(runs[1].Name(), "id1_k3_warp-prior");
  EXPECT_EQ(runs[2].Name(), "id1_k3_icef");
  EXPECT_EQ(runs[6].Name(), "id1_k3_nerface");
  EXPECT_EQ(runs[7].Name(), "id1_k5_icef-prior");
  EXPECT_EQ(runs[21].Name(), "id2_k3_icef-prior");
  EXPECT_EQ(runs.back().Name(), "id3_k10_nerface");
  std::set<std::string> names;
  for (const RunId& r : runs) names.insert(r.Name());
  EXPECT_EQ(names.size(), runs.size());
  // Training replicates: each run r times in a row, the first as before, each with its own seed.
  o.replicates = 2;
  o.ks = {5};
  o.methods = {"icef"};
  EXPECT_TRUE(o.Validate().ok());
  const std::vector<RunId> twice = PlanRuns(o);
  ASSERT_EQ(twice.size(), 3u * 2u);
  EXPECT_EQ(twice[0].Name(), "id1_k5_icef");
  EXPECT_EQ(twice[1].Name(), "id1_k5_icef_r1");
  EXPECT_EQ(twice[2].Name(), "id2_k5_icef");
  EXPECT_EQ(twice[0].TrainSeed(), 1);
  EXPECT_EQ(twice[1].TrainSeed(), 1001);
  EXPECT_EQ(o.ToJson()["replicates"], 2);
  o.replicates = 0;
  EXPECT_FALSE(o.Validate().ok());
}

TEST(BenchProtocolTest, ShardsPartitionTheRuns) {
  BenchOptions o;
  const std::vector<RunId> runs = PlanRuns(o);
  for (int n : {1, 2, 4, 7, 45, 50}) {
    std::multiset<std::string> seen;
    for (int i = 0; i < n; ++i) {
      const std::vector<RunId> shard = ShardRuns(runs, i, n);
      // Every n-th run starting at i.
      for (size_t j = 0; j < shard.size(); ++j) EXPECT_EQ(shard[j], runs[i + j * n]);
      EXPECT_LE(shard.size(), (runs.size() + n - 1) / n);
      for (const RunId& r : shard) seen.insert(r.Name());
    }
    EXPECT_EQ(seen.size(), runs.size()) << n;
    for (const RunId& r : runs) EXPECT_EQ(seen.count(r.Name()), 1u) << n;
  }
  const std::vector<RunId> s1 = ShardRuns(runs, 1, 4);
  ASSERT_GE(s1.size(), 2u);
  EXPECT_EQ(s1[0].Name(), "id1_k3_warp-prior");
  EXPECT_EQ(s1[1].Name(), "id1_k3_warp");
}

TEST(BenchProtocolTest, ParsesShardAndLists) {
  int i = -1, n = -1;
  ASSERT_TRUE(ParseShard("2/5", &i, &n).ok());
  EXPECT_EQ(i, 2);
  EXPECT_EQ(n, 5);
  for (const char* bad : {"5/5", "-1/3", "1/0", "1", "1/2x", "a/b"})
    EXPECT_FALSE(ParseShard(bad, &i, &n).ok()) << bad;
  const Result<std::vector<int>> ks = ParseIntList("3,5,10", "--k");
  ASSERT_TRUE(ks.ok());
  EXPECT_EQ(*ks, std::vector<int>({3, 5, 10}));
  EXPECT_FALSE(ParseIntList("3,,5", "--k").ok());
  EXPECT_FALSE(ParseIntList("3,x", "--k").ok());
  EXPECT_FALSE(ParseIntList("", "--k").ok());
}

TEST(BenchProtocolTest, ValidatesOptions) {
  BenchOptions o;
  EXPECT_FALSE(o.Validate().ok());  // no --out
  o.out_dir = "x";
  EXPECT_TRUE(o.Validate().ok());
  BenchOptions bad = o;
  bad.methods = {"icef", "fdnerf"};
  const Status s = bad.Validate();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("fdnerf"), std::string::npos) << s.message();
  bad = o;
  bad.ks = {0};
  EXPECT_FALSE(bad.Validate().ok());
  bad = o;
  bad.shard_index = 3;
  bad.shard_count = 3;
  EXPECT_FALSE(bad.Validate().ok());
  BenchOptions quick = o;
  quick.ApplyQuick();
  EXPECT_TRUE(quick.Validate().ok());
  EXPECT_EQ(PlanRuns(quick).size(), 7u);
  EXPECT_EQ(quick.resolution, 32);
}

// Test identities (seeds below 101) are reported, validation identities (101 and up) tuned on;
// neither kind of bench accepts the other's seeds.
TEST(BenchProtocolTest, TestAndValidationSeedsNeverMix) {
  BenchOptions o;
  o.out_dir = "x";
  o.identities = 100;
  EXPECT_TRUE(o.Validate().ok());  // seeds 1..100
  o.identities = 101;
  const Status overlap = o.Validate();
  ASSERT_FALSE(overlap.ok());
  EXPECT_NE(overlap.message().find("seeds 101 and up are validation identities"), std::string::npos)
      << overlap.message();
  BenchOptions v;
  v.out_dir = "x";
  v.ApplyValidation();
  EXPECT_TRUE(v.Validate().ok());
  EXPECT_EQ(v.identities, kDefaultValidationIdentities);
  EXPECT_EQ(v.ks, std::vector<int>({5}));
  const std::vector<RunId> runs = PlanRuns(v);
  EXPECT_EQ(runs.front().identity_seed, kFirstValidationSeed);
  EXPECT_EQ(runs.back().identity_seed, kFirstValidationSeed + kDefaultValidationIdentities - 1);
  EXPECT_NE(v.IdentityRole().find("validation"), std::string::npos);
  EXPECT_NE(o.IdentityRole().find("test identities"), std::string::npos);
  v.first_identity_seed = 100;
  EXPECT_FALSE(v.Validate().ok());
  EXPECT_TRUE(v.ToJson()["validation"].get<bool>());
}

// Merging two shard directories: runs are unioned; the same run in both must be identical.
TEST(BenchProtocolTest, MergesShardDirectories) {
  const fs::path dir = TempDir("merge");
  auto write_run = [&](const fs::path& bench, const RunId& id, double psnr) {
    RunRecord r;
    r.id = id;
    r.metrics.method = id.method;
    FrameMetrics f;
    f.file_path = "f.png";
    f.tier = Tier::kFar;
    f.delta = 1.0;
    f.psnr = psnr;
    r.metrics.frames = {f};
    r.metrics.tiers = AggregateTiers(r.metrics.frames);
    fs::create_directories(bench / "runs" / id.Name());
    ASSERT_TRUE(
        WriteFileAtomic(bench / "runs" / id.Name() / "metrics.json", FormatJson(RunRecordJson(r))).ok());
  };
  write_run(dir / "a", RunId{1, 3, "icef"}, 20);
  write_run(dir / "a", RunId{1, 3, "warp"}, 19);
  write_run(dir / "b", RunId{2, 3, "icef"}, 22);
  write_run(dir / "b", RunId{2, 3, "warp"}, 23);
  write_run(dir / "b", RunId{1, 3, "icef"}, 20);  // duplicate, identical
  std::ostringstream log;
  ASSERT_TRUE(MergeBench({dir / "a", dir / "b"}, dir / "merged", log).ok()) << log.str();
  const Result<std::vector<RunRecord>> runs = ReadRunRecords(dir / "merged");
  ASSERT_TRUE(runs.ok());
  EXPECT_EQ(runs->size(), 4u);
  const Result<Json> report = ReadJsonFile(dir / "merged" / "report.json");
  ASSERT_TRUE(report.ok());
  for (const Json& cell : (*report)["aggregate"]) {
    if (cell["method"] == "icef" && cell["tier"] == "far") {
      EXPECT_DOUBLE_EQ(cell["psnr"]["mean"].get<double>(), 21.0);
    }
  }

  EXPECT_EQ(log.str().find("warning"), std::string::npos) << log.str();

  write_run(dir / "c", RunId{1, 3, "icef"}, 25);  // conflicting duplicate: the first is kept, with a warning
  std::ostringstream log2;
  ASSERT_TRUE(MergeBench({dir / "a", dir / "c"}, dir / "merged2", log2).ok());
  EXPECT_NE(log2.str().find("warning: " + (dir / "c" / "runs" / "id1_k3_icef" / "metrics.json").string()),
            std::string::npos)
      << log2.str();
  const Result<RunRecord> kept = ReadRunRecord(dir / "merged2" / "runs" / "id1_k3_icef" / "metrics.json");
  ASSERT_TRUE(kept.ok());
  EXPECT_DOUBLE_EQ(*kept->metrics.frames[0].psnr, 20.0);

  // Different bench settings cannot be merged; a directory without runs/ is an error.
  ASSERT_TRUE(WriteFileAtomic(dir / "a" / "bench.json", R"({"steps": 10, "shard": "0/2"})").ok());
  ASSERT_TRUE(WriteFileAtomic(dir / "b" / "bench.json", R"({"steps": 10, "shard": "1/2"})").ok());
  EXPECT_TRUE(MergeBench({dir / "a", dir / "b"}, dir / "merged4", log).ok());
  // Other identity seeds of the same protocol merge too.
  ASSERT_TRUE(WriteFileAtomic(dir / "b" / "bench.json",
                              R"({"steps": 10, "identities": 3, "first_identity_seed": 104})")
                  .ok());
  EXPECT_TRUE(MergeBench({dir / "a", dir / "b"}, dir / "merged6", log).ok());
  // So do parts of one bench run by method or by K; the merged bench.json lists all of them.
  ASSERT_TRUE(
      WriteFileAtomic(dir / "a" / "bench.json", R"({"steps": 10, "ks": [3, 5], "methods": ["icef"]})").ok());
  ASSERT_TRUE(
      WriteFileAtomic(dir / "b" / "bench.json", R"({"steps": 10, "ks": [5], "methods": ["warp", "icef"]})")
          .ok());
  ASSERT_TRUE(MergeBench({dir / "a", dir / "b"}, dir / "merged7", log).ok()) << log.str();
  const Result<Json> parts = ReadJsonFile(dir / "merged7" / "bench.json");
  ASSERT_TRUE(parts.ok());
  EXPECT_EQ((*parts)["ks"], Json::parse("[3, 5]"));
  EXPECT_EQ((*parts)["methods"], Json::parse(R"(["icef", "warp"])"));
  EXPECT_EQ((*parts)["steps"], 10);
  ASSERT_TRUE(WriteFileAtomic(dir / "a" / "bench.json", R"({"steps": 10, "shard": "0/2"})").ok());
  ASSERT_TRUE(WriteFileAtomic(dir / "b" / "bench.json", R"({"steps": 20, "shard": "1/2"})").ok());
  const Status differ = MergeBench({dir / "a", dir / "b"}, dir / "merged5", log);
  ASSERT_FALSE(differ.ok());
  EXPECT_NE(differ.message().find("settings differ"), std::string::npos) << differ.message();
  EXPECT_FALSE(MergeBench({dir / "missing"}, dir / "merged3", log).ok());
  fs::remove_all(dir);
}

TEST(BenchProtocolTest, MergedValidationBenchDrawsTheWorstRunsTrainingViewsFromItsShard) {
  // Two validation shards; the worst run by training-view fit (id102_k5_icef, in shard b) has its
  // training-view pairs there. The merged report draws its sheet from shard b and links it.
  const fs::path dir = TempDir("merge_sheet");
  auto write_run = [&](const fs::path& bench, const RunId& id, double face_psnr) {
    RunRecord r;
    r.id = id;
    r.metrics.method = id.method;
    FrameMetrics f;
    f.file_path = "f.png";
    f.tier = Tier::kObserved;
    f.psnr = face_psnr - 2;
    r.metrics.frames = {f};
    r.metrics.tiers = AggregateTiers(r.metrics.frames);
    r.metrics.train_fit =
        TrainingFit::Of({TrainFrameFit{"images/train_000.png", face_psnr, 300, 0.9, face_psnr, ""}});
    fs::create_directories(bench / "runs" / id.Name());
    ASSERT_TRUE(
        WriteFileAtomic(bench / "runs" / id.Name() / "metrics.json", FormatJson(RunRecordJson(r))).ok());
    ASSERT_TRUE(WriteFileAtomic(bench / "bench.json", R"({"validation": true, "steps": 10})").ok());
  };
  write_run(dir / "a", RunId{101, 5, "icef"}, 35);
  write_run(dir / "b", RunId{102, 5, "icef"}, 30);
  const fs::path renders = dir / "b" / "runs" / "id102_k5_icef" / "renders";
  fs::create_directories(renders);
  ASSERT_TRUE(WritePng(renders / "fit_train_000_vs_truth.png", Image(4, 2, 3, 0.5f)).ok());
  ASSERT_TRUE(WritePng(renders / "fit_train_001_vs_truth.png", Image(4, 2, 3, 0.25f)).ok());
  std::ostringstream log;
  ASSERT_TRUE(MergeBench({dir / "a", dir / "b"}, dir / "merged", log).ok()) << log.str();
  const Result<Image> sheet = ReadImage(dir / "merged" / "worst_id102_k5_icef_training_views.png");
  ASSERT_TRUE(sheet.ok()) << sheet.status().message();
  EXPECT_EQ(sheet->height, 4);
  EXPECT_FALSE(fs::exists(dir / "merged" / "runs" / "id102_k5_icef" / "renders"));  // the renders stay in b
  const Result<std::string> md = ReadFile(dir / "merged" / "report.md");
  ASSERT_TRUE(md.ok());
  EXPECT_NE(md->find("[worst_id102_k5_icef_training_views.png](worst_id102_k5_icef_training_views.png)"),
            std::string::npos)
      << *md;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace icef::eval
