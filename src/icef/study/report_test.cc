#include "icef/study/report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "icef/io/atomic_file.h"
#include "icef/io/image.h"

namespace icef::eval {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("icef_report_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// A run whose far tier has the given PSNR, identity distance (cosine = 1 - distance / 2; distance
// to the ground truth + 0.1) and expression gain, and whose observed tier has PSNR + 10.
RunRecord MakeRun(uint64_t seed, int k, const std::string& method, double far_psnr, double far_id,
                  double far_gain = 0.8) {
  RunRecord r;
  r.id = RunId{seed, k, method};
  r.metrics.method = method;
  r.metrics.identity_available = true;
  r.train_steps = 100;
  r.train_seconds = 2.0;
  r.eval_seconds = 0.5;
  FrameMetrics obs;
  obs.file_path = "o.png";
  obs.tier = Tier::kObserved;
  obs.psnr = far_psnr + 10;
  obs.ssim = 0.9;
  obs.id_distance = 0.1;
  obs.id_cosine = 0.99;
  obs.id_distance_gt = 0.2;
  FrameMetrics far;
  far.file_path = "f.png";
  far.tier = Tier::kFar;
  far.delta = 1.0 + 0.1 * seed;
  far.psnr = far_psnr;
  far.ssim = 0.5;
  far.id_distance = far_id;
  far.id_cosine = 1.0 - far_id / 2;
  far.id_distance_gt = far_id + 0.1;
  far.expr_gain = far_gain;
  far.expr_corr = far_gain > 0 ? 0.9 : 0.0;
  far.expr_true_rms = 0.05;
  far.psnr_neutral_floor = 26.0;
  far.id_distance_reference = 0.4;
  far.id_excess = far_id - 0.4;
  r.metrics.frames = {obs, far};
  r.metrics.tiers = AggregateTiers(r.metrics.frames);
  return r;
}

std::vector<RunRecord> ThreeIdentities() {
  // icef: better identity than warp on all identities, worse PSNR on 2 of 3.
  return {MakeRun(1, 3, "icef", 20, 0.30), MakeRun(2, 3, "icef", 22, 0.40), MakeRun(3, 3, "icef", 24, 0.50),
          MakeRun(1, 3, "warp", 21, 0.50), MakeRun(2, 3, "warp", 23, 0.60), MakeRun(3, 3, "warp", 23, 0.70)};
}

TEST(ReportTest, SpreadOverIdentities) {
  const auto s = Spread::Of({1.0, 2.0, 6.0});
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->n, 3);
  EXPECT_DOUBLE_EQ(s->mean, 3.0);
  EXPECT_DOUBLE_EQ(s->std, std::sqrt(7.0));  // sample std: (4 + 1 + 9) / 2
  EXPECT_DOUBLE_EQ(s->min, 1.0);
  EXPECT_DOUBLE_EQ(s->max, 6.0);
  EXPECT_FALSE(Spread::Of({}).has_value());
  EXPECT_DOUBLE_EQ(Spread::Of({4.0})->std, 0.0);
}

TEST(ReportTest, AggregatesPerKMethodTierAndComparesFarTier) {
  const Aggregate a = AggregateRuns(ThreeIdentities());
  EXPECT_EQ(a.ks, std::vector<int>({3}));
  EXPECT_EQ(a.methods, std::vector<std::string>({"icef", "warp"}));  // AllMethods() order
  EXPECT_EQ(a.identities, std::vector<uint64_t>({1, 2, 3}));
  const AggregateCell* far = a.Find(3, "icef", Tier::kFar);
  ASSERT_NE(far, nullptr);
  EXPECT_EQ(far->runs, 3);
  EXPECT_DOUBLE_EQ(far->Get(Metric::kPsnr)->mean, 22.0);
  EXPECT_DOUBLE_EQ(far->Get(Metric::kPsnr)->std, 2.0);
  EXPECT_DOUBLE_EQ(far->Get(Metric::kIdDistance)->mean, 0.4);
  EXPECT_DOUBLE_EQ(far->Get(Metric::kIdDistance)->min, 0.3);
  EXPECT_DOUBLE_EQ(far->Get(Metric::kIdDistance)->max, 0.5);
  EXPECT_NEAR(far->delta->mean, 1.2, 1e-12);
  EXPECT_DOUBLE_EQ(far->Get(Metric::kIdShareUnder06)->mean, 1.0);
  EXPECT_FALSE(far->Get(Metric::kLpips).has_value());
  const AggregateCell* warp_far = a.Find(3, "warp", Tier::kFar);
  EXPECT_NEAR(warp_far->Get(Metric::kIdShareUnder06)->mean, 1.0 / 3.0, 1e-12);
  const AggregateCell* near = a.Find(3, "icef", Tier::kNear);
  ASSERT_NE(near, nullptr);
  EXPECT_EQ(near->runs, 0);
  EXPECT_FALSE(near->Get(Metric::kPsnr).has_value());

  int checked = 0;
  for (const Comparison& c : a.far_comparisons) {
    EXPECT_EQ(c.other, "warp");
    EXPECT_EQ(c.paired, 3);
    if (c.metric == Metric::kPsnr) {
      EXPECT_FALSE(c.icef_better);  // 22 vs 22.33
      EXPECT_EQ(c.icef_wins, 1);    // identity 3: 24 > 23
      ++checked;
    } else if (c.metric == Metric::kIdDistance) {
      EXPECT_TRUE(c.icef_better);
      EXPECT_EQ(c.icef_wins, 3);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 2);

  // The pair verdict: same expression gain, better identity, worse PSNR (22 vs 22.33).
  ASSERT_EQ(a.verdicts.size(), 3u);  // near, moderate (no data) and far
  const PairVerdict& v = a.verdicts.back();
  EXPECT_EQ(v.tier, Tier::kFar);
  EXPECT_EQ(v.outcome, Outcome::kWorsePsnr);
  EXPECT_EQ(a.verdicts.front().outcome, Outcome::kNoData);
  const std::vector<std::string> verdict = Verdict(a);
  ASSERT_GE(verdict.size(), 2u);
  EXPECT_NE(verdict[0].find("**far tier, icef vs the baselines**: icef is **not better** in any comparison"),
            std::string::npos)
      << verdict[0];
  EXPECT_NE(verdict[0].find("K=3 vs warp: not better on PSNR (psnr 22.00"), std::string::npos) << verdict[0];
}

// The rule at the heart of the protocol: a model that renders no expression (expr_gain 0) loses to
// one that does, however good its PSNR and identity numbers are (a still face scores the neutral
// floor's PSNR and a small identity distance).
TEST(ReportTest, AFaceThatDoesNotMoveNeverWins) {
  std::vector<RunRecord> runs;
  for (uint64_t seed : {1, 2, 3}) {
    runs.push_back(MakeRun(seed, 5, "icef", 24.0, 0.40, 0.6 + 0.05 * seed));  // moves: gain 0.65 .. 0.75
    runs.push_back(MakeRun(seed, 5, "warp", 27.0, 0.20, 0.0));  // still: better PSNR and identity
  }
  // Seen from either side: the still face is never better, and the verdict names its under-expression.
  Aggregate a = AggregateRuns(runs);
  EXPECT_EQ(ComparePair(a, 5, Tier::kFar, "warp", "icef").outcome, Outcome::kUnderExpresses);
  EXPECT_EQ(ComparePair(a, 5, Tier::kFar, "icef", "warp").outcome, Outcome::kWorseIdentity);
  const std::vector<std::string> verdict = Verdict(a);
  std::string all;
  for (const std::string& line : verdict) all += line + "\n";
  EXPECT_NE(all.find("**Under-expression** in the far tier (less than half of the expression): `warp` (0%)"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("`icef` -/-/0.70"), std::string::npos) << all;
  // Even where the moving model's gain is uncertain (large spread), a gain below the floor never wins.
  runs[0] = MakeRun(1, 5, "icef", 20.0, 0.60, 0.0);
  runs[2] = MakeRun(2, 5, "icef", 20.0, 0.60, 0.5);
  a = AggregateRuns(runs);
  EXPECT_EQ(ComparePair(a, 5, Tier::kFar, "warp", "icef").outcome, Outcome::kUnderExpresses);
  // Equal gains within the spread: identity and PSNR decide.
  std::vector<RunRecord> close = {MakeRun(1, 5, "icef", 24.0, 0.3, 0.70),
                                  MakeRun(1, 5, "warp", 23.0, 0.4, 0.71)};
  EXPECT_EQ(ComparePair(AggregateRuns(close), 5, Tier::kFar, "icef", "warp").outcome, Outcome::kBetter);
  close[0] = MakeRun(1, 5, "icef", 24.0, 0.3, 0.60);
  EXPECT_EQ(ComparePair(AggregateRuns(close), 5, Tier::kFar, "icef", "warp").outcome,
            Outcome::kUnderExpresses);
}

TEST(ReportTest, NoVerdictWithoutBaseline) {
  const Aggregate a = AggregateRuns({MakeRun(1, 3, "icef", 20, 0.3), MakeRun(1, 3, "icef-no-id", 20, 0.4)});
  const std::vector<std::string> verdict = Verdict(a);
  ASSERT_GE(verdict.size(), 1u);
  EXPECT_NE(verdict[0].find("No verdict"), std::string::npos);
}

TEST(ReportTest, WritesMarkdownJsonAndPlots) {
  const fs::path dir = TempDir("write");
  const std::vector<RunRecord> runs = ThreeIdentities();
  // Stored as bench runs and read back (sorted by identity, K, method).
  for (auto it = runs.rbegin(); it != runs.rend(); ++it) {
    fs::create_directories(dir / "runs" / it->id.Name());
    ASSERT_TRUE(
        WriteFileAtomic(dir / "runs" / it->id.Name() / "metrics.json", FormatJson(RunRecordJson(*it))).ok());
  }
  const Result<std::vector<RunRecord>> read = ReadRunRecords(dir);
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_EQ(read->size(), 6u);
  EXPECT_EQ((*read)[0].id.Name(), "id1_k3_icef");
  EXPECT_EQ((*read)[1].id.Name(), "id1_k3_warp");
  EXPECT_EQ((*read)[5].id.Name(), "id3_k3_warp");
  EXPECT_DOUBLE_EQ((*read)[0].train_seconds, 2.0);

  ReportContext context;
  context.settings = Json{{"steps", 100}};
  context.identity_role = "test identities";
  context.tier_thresholds = std::array<double, 2>{0.35, 0.8};
  ASSERT_TRUE(WriteReport(dir, *read, context).ok());
  const Result<std::string> md = ReadFile(dir / "report.md");
  ASSERT_TRUE(md.ok());
  EXPECT_NE(md->find("## Verdict (computed)"), std::string::npos);
  EXPECT_NE(md->find("- identities (seeds): 1, 2, 3 (test identities"), std::string::npos) << *md;
  EXPECT_NE(md->find("- tiers by delta: observed = 0, near (0, 0.35], moderate (0.35, 0.80], far > 0.80"),
            std::string::npos);
  EXPECT_NE(md->find("expr_gain"), std::string::npos);
  EXPECT_NE(md->find("FDNeRF and NeRFFaceEditing proper are not available"), std::string::npos);
  EXPECT_NE(
      md->find("| far | `icef` | 3 | 1.20 | 22.00 ± 2.00 [20.00, 24.00] | 26.00 ± 0.00 [26.00, 26.00] |"),
      std::string::npos)
      << *md;
  EXPECT_NE(md->find("LPIPS: unavailable"), std::string::npos);
  EXPECT_NE(md->find("| id2_k3_warp | 100 |"), std::string::npos);
  const Result<Json> json = ReadJsonFile(dir / "report.json");
  ASSERT_TRUE(json.ok());
  bool found = false;
  for (const Json& cell : (*json)["aggregate"])
    if (cell["method"] == "warp" && cell["tier"] == "far") {
      EXPECT_NEAR(cell["psnr"]["mean"].get<double>(), 67.0 / 3.0, 1e-12);
      EXPECT_DOUBLE_EQ(cell["id_distance"]["max"].get<double>(), 0.7);
      EXPECT_TRUE(cell["lpips"].is_null());
      found = true;
    }
  EXPECT_TRUE(found);
  EXPECT_EQ((*json)["runs"].size(), 6u);
  EXPECT_EQ((*json)["verdict"].size(), 3u);  // far (baselines), expression, identity drift
  EXPECT_EQ((*json)["pair_verdicts"].size(), 3u);
  EXPECT_EQ((*json)["tier_thresholds"][1].get<double>(), 0.8);
  // Plot data: one block per (K, method), rows (delta, mean, std, ...) per tier with values.
  const Result<std::string> dat = ReadFile(dir / "plots" / "psnr.dat");
  ASSERT_TRUE(dat.ok());
  EXPECT_NE(dat->find("# K=3 method=icef\n0 32 2 30 34 3\n1.2"), std::string::npos) << *dat;
  EXPECT_FALSE(fs::exists(dir / "plots" / "lpips.dat"));  // no values, no plot
  if (std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    EXPECT_GT(fs::file_size(dir / "plots" / "psnr.png"), 1000u);
    EXPECT_GT(fs::file_size(dir / "plots" / "id_distance.svg"), 1000u);
    std::ifstream pdf(dir / "plots" / "id_distance.pdf", std::ios::binary);
    std::string magic(5, '\0');
    pdf.read(magic.data(), 5);
    EXPECT_EQ(magic, "%PDF-");
    EXPECT_GT(fs::file_size(dir / "plots" / "id_distance.pdf"), 1000u);
    EXPECT_NE(md->find("![plots/psnr.png](plots/psnr.png)"), std::string::npos);
  }
  fs::remove_all(dir);
}

TEST(ReportTest, TrainingReplicatesCountOncePerIdentityWithTheirSpread) {
  // icef on three identities, the first two trained twice (far PSNR 20 / 22 and 22 / 26).
  std::vector<RunRecord> runs = ThreeIdentities();
  RunRecord again1 = MakeRun(1, 3, "icef", 22, 0.34, 0.6);
  again1.id.replicate = 1;
  RunRecord again2 = MakeRun(2, 3, "icef", 26, 0.40);
  again2.id.replicate = 1;
  runs.push_back(again1);
  runs.push_back(again2);
  EXPECT_EQ(again1.id.Name(), "id1_k3_icef_r1");
  EXPECT_EQ(again1.id.TrainSeed(), 1001);
  EXPECT_EQ(runs[0].id.TrainSeed(), 1);

  const std::vector<RunRecord> pooled = PoolReplicates(runs);
  ASSERT_EQ(pooled.size(), 6u);  // one per (identity, K, method)
  const TierMetrics& far1 = pooled[0].metrics.tiers[TierIndex(Tier::kFar)];
  EXPECT_EQ(pooled[0].id.Name(), "id1_k3_icef");
  EXPECT_DOUBLE_EQ(*far1.psnr, 21.0);
  EXPECT_DOUBLE_EQ(*far1.id_distance, 0.32);
  EXPECT_DOUBLE_EQ(*far1.expr_gain, 0.7);
  EXPECT_EQ(far1.count, 1);  // counts from the first replicate
  EXPECT_DOUBLE_EQ(*pooled[1].metrics.tiers[TierIndex(Tier::kFar)].psnr, 24.0);
  EXPECT_DOUBLE_EQ(*pooled[2].metrics.tiers[TierIndex(Tier::kFar)].psnr, 24.0);  // identity 3: one run

  const Aggregate a = AggregateRuns(runs);
  const AggregateCell* icef = a.Find(3, "icef", Tier::kFar);
  ASSERT_NE(icef, nullptr);
  EXPECT_EQ(icef->runs, 3);                                // identities, not trainings
  EXPECT_DOUBLE_EQ(icef->Get(Metric::kPsnr)->mean, 23.0);  // (21 + 24 + 24) / 3
  // The spread: identities 1 and 2 ranges 2 and 4 dB (mean 3); expr_gain 0.2 and 0.
  const ReplicateSpreadCell* spread = nullptr;
  for (const ReplicateSpreadCell& c : a.replicate_spread)
    if (c.method == "icef" && c.tier == Tier::kFar) spread = &c;
  ASSERT_NE(spread, nullptr);
  EXPECT_EQ(spread->identities, 2);
  EXPECT_EQ(spread->replicates, 2);
  EXPECT_DOUBLE_EQ(*spread->psnr_range, 3.0);
  EXPECT_NEAR(*spread->expr_gain_range, 0.1, 1e-12);
  for (const ReplicateSpreadCell& c : a.replicate_spread) EXPECT_NE(c.method, "warp");  // trained once
  EXPECT_TRUE(AggregateRuns(ThreeIdentities()).replicate_spread.empty());

  // Written and read back: the replicate survives, the report has the spread table.
  const fs::path dir = TempDir("replicates");
  for (const RunRecord& r : runs) {
    fs::create_directories(dir / "runs" / r.id.Name());
    ASSERT_TRUE(
        WriteFileAtomic(dir / "runs" / r.id.Name() / "metrics.json", FormatJson(RunRecordJson(r))).ok());
  }
  const Result<std::vector<RunRecord>> read = ReadRunRecords(dir);
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_EQ(read->size(), 8u);
  EXPECT_EQ((*read)[1].id.Name(), "id1_k3_icef_r1");
  ASSERT_TRUE(WriteReport(dir, *read, ReportContext()).ok());
  const Result<std::string> md = ReadFile(dir / "report.md");
  ASSERT_TRUE(md.ok());
  EXPECT_NE(md->find("## Training-seed spread"), std::string::npos) << *md;
  EXPECT_NE(md->find("| 3 | `icef` | far | 2 | 2 | 3.00 | 0.100 |"), std::string::npos) << *md;
  fs::remove_all(dir);
}

// `run` with a training-view fit of two views: face PSNR face_psnr -+ 1, full image face_psnr - 5.
RunRecord WithTrainFit(RunRecord run, double face_psnr) {
  run.metrics.train_fit =
      TrainingFit::Of({TrainFrameFit{"images/train_000.png", face_psnr - 1, 300, 0.9, face_psnr - 5, ""},
                       TrainFrameFit{"images/train_001.png", face_psnr + 1, 300, 0.9, face_psnr - 5, ""}});
  return run;
}

TEST(ReportTest, TrainingViewFitAndPerIdentityTable) {
  // Identity 2 fits its training views worst (mean 28.5 over its two runs); identity 1 has the lowest
  // observed PSNR (30 and 31).
  std::vector<RunRecord> runs = ThreeIdentities();
  const double fit[] = {30, 33, 35, 32, 24, 34};  // icef 1, 2, 3, then warp 1, 2, 3
  for (size_t i = 0; i < runs.size(); ++i) runs[i] = WithTrainFit(runs[i], fit[i]);
  const Aggregate a = AggregateRuns(runs);
  const TrainFitCell* icef = a.FindTrainFit(3, "icef");
  ASSERT_NE(icef, nullptr);
  EXPECT_EQ(icef->runs, 3);
  EXPECT_NEAR(icef->face_psnr->mean, 98.0 / 3.0, 1e-12);
  EXPECT_DOUBLE_EQ(icef->face_psnr_min->min, 29.0);
  EXPECT_DOUBLE_EQ(icef->psnr->max, 30.0);

  ReportContext validation;
  validation.identity_role = "validation identities: for tuning";
  const std::string md = ReportMarkdown(a, runs, validation, {});
  EXPECT_NE(md.find("### K = 3, training-view fit\n\n| method | runs | face_psnr | face_psnr_min | psnr |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| `icef` | 3 | 32.67 ± 2.52 [30.00, 35.00] | 31.67 ± 2.52 [29.00, 34.00] |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| id2_k3_warp | 100 | 2.0s | 0.5s | 2 | 0 | 24.00 |"), std::string::npos) << md;
  EXPECT_NE(md.find("## Per identity"), std::string::npos) << md;
  EXPECT_NE(
      md.find(
          "| identity | method | K | train face_psnr | worst view | face detail | observed psnr | far psnr | "
          "observed region_psnr | observed id_distance_gt | far expr_gain |"),
      std::string::npos)
      << md;
  // Seed 2, warp: far PSNR 23 (observed 33), no region PSNR, id_distance_gt 0.2 observed, gain 0.8.
  EXPECT_NE(md.find("| 2 | `warp` | 3 | 24.00 | 23.00 | 0.90 | 33.00 | 23.00 | - | 0.200 | 0.800 |"),
            std::string::npos)
      << md;
  EXPECT_LT(md.find("| 1 | `icef` |"), md.find("| 1 | `warp` |"));
  EXPECT_LT(md.find("| 1 | `warp` |"), md.find("| 2 | `icef` |"));
  EXPECT_NE(md.find("**Worst identity by training-view face PSNR**: seed 2 (mean 28.50 dB over its 2 runs; "
                    "lowest run `id2_k3_warp`, 24.00 dB)."),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("**Worst identity by observed PSNR**: seed 1 (mean 30.50 dB over its 2 runs; lowest run "
                    "`id1_k3_icef`, 30.00 dB)."),
            std::string::npos)
      << md;
  const Json json = ReportJson(a, runs, validation);
  ASSERT_EQ(json["train_fit"].size(), 2u);
  EXPECT_EQ(json["train_fit"][1]["method"], "warp");
  EXPECT_DOUBLE_EQ(json["train_fit"][1]["face_psnr"]["min"].get<double>(), 24.0);
  EXPECT_EQ(json["worst_identity"]["train_fit_face_psnr"]["identity_seed"], 2);
  EXPECT_EQ(json["worst_identity"]["observed_psnr"]["worst_run"], "id1_k3_icef");
  EXPECT_DOUBLE_EQ(json["runs"][0]["train_fit_face_psnr"].get<double>(), 30.0);

  // A test bench: the training-view fit table, no per-identity table; a flag turns it on.
  ReportContext test;
  test.identity_role = "test identities";
  const std::string test_md = ReportMarkdown(a, runs, test, {});
  EXPECT_NE(test_md.find("### K = 3, training-view fit"), std::string::npos);
  EXPECT_EQ(test_md.find("## Per identity"), std::string::npos);
  EXPECT_FALSE(ReportJson(a, runs, test).contains("worst_identity"));
  test.per_identity = true;
  EXPECT_NE(ReportMarkdown(a, runs, test, {}).find("## Per identity"), std::string::npos);

  // Runs from before the training-view fit: no fit table, '-' in the run and identity tables.
  const std::vector<RunRecord> old = ThreeIdentities();
  const std::string old_md = ReportMarkdown(AggregateRuns(old), old, validation, {});
  EXPECT_EQ(old_md.find("training-view fit\n\n| method"), std::string::npos) << old_md;
  EXPECT_NE(old_md.find("| id2_k3_warp | 100 | 2.0s | 0.5s | 2 | 0 | - |"), std::string::npos) << old_md;
  EXPECT_NE(old_md.find("**Worst identity by training-view face PSNR**: no values."), std::string::npos)
      << old_md;
}

TEST(ReportTest, WorstIdentityLinksItsTrainingViewsBesideTheirTruth) {
  // Bench runs with icef eval's training-view pairs for the worst run by training-view fit
  // (id2_k3_warp) only; the worst run by observed PSNR (id1_k3_icef) has none.
  const fs::path dir = TempDir("worst");
  std::vector<RunRecord> runs = ThreeIdentities();
  const double fit[] = {30, 33, 35, 32, 24, 34};
  for (size_t i = 0; i < runs.size(); ++i) runs[i] = WithTrainFit(runs[i], fit[i]);
  const fs::path renders = dir / "runs" / "id2_k3_warp" / "renders";
  fs::create_directories(renders);
  ASSERT_TRUE(WritePng(renders / "fit_train_000_vs_truth.png", Image(4, 2, 3, 0.5f)).ok());
  ASSERT_TRUE(WritePng(renders / "fit_train_001_vs_truth.png", Image(4, 2, 3, 0.25f)).ok());
  ReportContext validation;
  validation.identity_role = "validation identities: for tuning";
  ASSERT_TRUE(WriteReport(dir, runs, validation).ok());

  const Result<Image> sheet = ReadImage(dir / "worst_id2_k3_warp_training_views.png");
  ASSERT_TRUE(sheet.ok()) << sheet.status().message();
  EXPECT_EQ(sheet->height, 4);
  EXPECT_FALSE(fs::exists(dir / "worst_id1_k3_icef_training_views.png"));
  const Result<std::string> md = ReadFile(dir / "report.md");
  ASSERT_TRUE(md.ok());
  EXPECT_NE(md->find("lowest run `id2_k3_warp`, 24.00 dB). Its training views, truth left and render right: "
                     "[worst_id2_k3_warp_training_views.png](worst_id2_k3_warp_training_views.png)"),
            std::string::npos)
      << *md;
  EXPECT_NE(md->find("lowest run `id1_k3_icef`, 30.00 dB).\n"), std::string::npos) << *md;
  const Result<Json> json = ReadJsonFile(dir / "report.json");
  ASSERT_TRUE(json.ok());
  EXPECT_EQ((*json)["worst_identity"]["train_fit_face_psnr"]["training_views"],
            "worst_id2_k3_warp_training_views.png");
  EXPECT_FALSE((*json)["worst_identity"]["observed_psnr"].contains("training_views"));

  // A test bench has no worst identity and writes no sheet.
  const fs::path test_dir = TempDir("worst_test_bench");
  fs::create_directories(test_dir / "runs");
  fs::copy(dir / "runs", test_dir / "runs", fs::copy_options::recursive);
  ASSERT_TRUE(WriteReport(test_dir, runs, ReportContext()).ok());
  EXPECT_FALSE(fs::exists(test_dir / "worst_id2_k3_warp_training_views.png"));
  fs::remove_all(dir);
  fs::remove_all(test_dir);
}

TEST(ReportTest, RunRecordErrors) {
  const fs::path dir = TempDir("errors");
  RunRecord r = MakeRun(1, 3, "icef", 20, 0.3);
  Json j = RunRecordJson(r);
  j.erase("run");
  ASSERT_TRUE(WriteFileAtomic(dir / "a.json", FormatJson(j)).ok());
  Result<RunRecord> read = ReadRunRecord(dir / "a.json");
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.status().message().find("run: missing"), std::string::npos);
  j = RunRecordJson(r);
  j["run"]["method"] = "warp";
  ASSERT_TRUE(WriteFileAtomic(dir / "b.json", FormatJson(j)).ok());
  read = ReadRunRecord(dir / "b.json");
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.status().message().find("differs"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace icef::eval
