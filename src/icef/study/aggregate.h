// The bench's numbers: per tier, per method, per K, the mean and spread (sample std, min, max) over
// identities of every metric, computed from the per-run metrics.json files (RunRecord), and the
// verdict on the paper's claim (docs/design.md §6) derived from them. study/report.h writes them.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "icef/eval/evaluate.h"
#include "icef/io/json_util.h"

namespace icef::eval {

// One bench run: an identity seed, a number of training frames K and a method.
struct RunId {
  uint64_t identity_seed = 1;
  int k = 3;
  std::string method;
  // Training replicate: 0 trains with the identity seed, r > 0 with identity_seed + 1000 r.
  int replicate = 0;
  // Directory name under runs/: "id<seed>_k<K>_<method>", e.g. "id1_k3_icef"; replicates r > 0
  // add "_r<r>".
  std::string Name() const;
  int64_t TrainSeed() const { return static_cast<int64_t>(identity_seed) + 1000 * int64_t(replicate); }
  bool operator==(const RunId& o) const = default;
};

// A finished run: its metrics.json plus how it was trained.
struct RunRecord {
  RunId id;
  EvalResult metrics;
  int64_t train_steps = 0;
  double train_seconds = 0;
  double eval_seconds = 0;
};

// The metrics a report aggregates, in table order.
// kIdDistanceReference: the ground truth's own drift (GT vs GT neutral), the floor a perfect model shows.
// The expression metrics (kExprGain, kExprCorr, kExprGainCoarse, kRegionPsnr) and kPsnrNeutralFloor,
// kIdExcess: eval/evaluate.h.
enum class Metric {
  kPsnr,
  kPsnrNeutralFloor,
  kSsim,
  kLpips,
  kExprGain,
  kExprCorr,
  kExprGainCoarse,
  kRegionPsnr,
  kIdCosine,
  kIdDistance,
  kIdDistanceGt,
  kIdShareUnder06,
  kIdDistanceReference,
  kIdExcess
};
constexpr int kNumMetrics = 14;
const std::array<Metric, kNumMetrics>& AllMetrics();
const char* MetricName(Metric metric);  // the metrics.json key, e.g. "id_distance"
const char* MetricLabel(
    Metric metric);  // axis label, e.g. "identity distance to own neutral (lower = better)"
bool HigherIsBetter(Metric metric);
const char* MetricFormat(Metric metric);  // printf format of its values in the reports, e.g. "%.2f" for PSNR
std::optional<double> TierValue(const TierMetrics& tier, Metric metric);

// Mean and spread of values over identities.
struct Spread {
  int n = 0;
  double mean = 0;
  double std = 0;  // sample standard deviation (n - 1); 0 when n == 1
  double min = 0;
  double max = 0;
  static std::optional<Spread> Of(const std::vector<double>& values);  // nullopt when empty
  Json ToJson() const;
};

// One (K, method, tier) cell: spreads over the runs (identities) that have a value.
struct AggregateCell {
  int k = 0;
  std::string method;
  Tier tier = Tier::kObserved;
  int runs = 0;                 // runs contributing (identities)
  int frames = 0;               // test frames over those runs
  std::optional<Spread> delta;  // of the runs' mean delta
  std::array<std::optional<Spread>, kNumMetrics> metrics;
  std::optional<Spread> Get(Metric m) const { return metrics[static_cast<int>(m)]; }
};

// The far-tier comparison of icef against one other method at one K, on one metric.
struct Comparison {
  int k = 0;
  std::string other;
  Metric metric = Metric::kPsnr;
  double icef_mean = 0;
  double other_mean = 0;
  bool icef_better = false;  // by the mean, in the metric's direction
  int paired = 0;            // identities with both values
  int icef_wins = 0;         // of those, where icef is better
  Json ToJson() const;
};

// The verdict rule (docs/design.md §6): method A is better than B in a tier only where A reproduces at
// least kMinExpressionGain of the expression, its expr_gain is not lower than B's beyond the spread
// over identities (max of the two sample stds, at least kGainTolerance), and it is better on both
// id_distance_gt and PSNR. A face that does not move (expr_gain 0) therefore never wins.
constexpr double kMinExpressionGain = 0.1;
constexpr double kGainTolerance = 0.02;

enum class Outcome {
  kBetter,          // all conditions hold
  kUnderExpresses,  // A's expr_gain is below kMinExpressionGain or lower than B's beyond the spread
  kWorseIdentity,   // expression fine, id_distance_gt not better
  kWorsePsnr,       // expression and identity fine, PSNR not better
  kNoData,          // a metric is missing
};
const char* OutcomeName(Outcome outcome);

// icef against one other method at one K in one tier, by the rule above.
struct PairVerdict {
  int k = 0;
  Tier tier = Tier::kFar;
  std::string method;  // "icef"
  std::string other;
  Outcome outcome = Outcome::kNoData;
  Json ToJson() const;
};
PairVerdict ComparePair(const struct Aggregate& aggregate, int k, Tier tier, const std::string& method,
                        const std::string& other);

// The training-view fit (EvalResult::train_fit) of one (K, method): spreads over the runs
// (identities) that measured it.
struct TrainFitCell {
  int k = 0;
  std::string method;
  int runs = 0;                         // runs that measured the fit
  std::optional<Spread> face_psnr;      // of the runs' mean face-region PSNR
  std::optional<Spread> face_psnr_min;  // of the runs' worst training view
  std::optional<Spread> psnr;           // of the runs' mean full-image PSNR
  Json ToJson() const;
};

// Training-seed spread of one (K, method, tier): over the identities trained more than once
// (BenchOptions::replicates), the mean of each identity's range (max - min over its replicates).
struct ReplicateSpreadCell {
  int k = 0;
  std::string method;
  Tier tier = Tier::kObserved;
  int identities = 0;                // identities with two or more replicates
  int replicates = 0;                // the most replicates of any of them
  std::optional<double> psnr_range;  // dB
  std::optional<double> expr_gain_range;
  Json ToJson() const;
};

// One record per (identity, K, method): each tier's and the training-view fit's numbers averaged
// over the run's training replicates (counts from the first replicate), replicate 0, the per-frame
// metrics of the first. Runs without replicates come back unchanged.
std::vector<RunRecord> PoolReplicates(const std::vector<RunRecord>& runs);

struct Aggregate {
  std::vector<int> ks;                      // ascending
  std::vector<std::string> methods;         // in AllMethods() order, then others by name
  std::vector<uint64_t> identities;         // ascending
  std::vector<AggregateCell> cells;         // k-major, then method, then tier
  std::vector<Comparison> far_comparisons;  // icef vs every other method, far tier, per K, per metric
  std::vector<PairVerdict> verdicts;    // icef and icef-prior vs every other method, per K, near/moderate/far
  std::vector<TrainFitCell> train_fit;  // k-major, then method (every (K, method) with runs)
  std::vector<ReplicateSpreadCell>
      replicate_spread;  // k-major, then method, then tier; empty without replicates
  const AggregateCell* Find(int k, const std::string& method, Tier tier) const;
  const TrainFitCell* FindTrainFit(int k, const std::string& method) const;
};

// Spreads over identities of every metric; an identity's training replicates count once, as
// their mean (PoolReplicates), and their spread goes to replicate_spread.
Aggregate AggregateRuns(const std::vector<RunRecord>& runs);

// Spreads over identities of every metric; an identity's training replicates count once, as
// their mean (PoolReplicates), and their spread goes to replicate_spread.
Aggregate AggregateRuns(const std::vector<RunRecord>& runs);

// The verdict lines (markdown bullets): per novel tier, icef against the baselines (warp, nerface)
// and the other methods by the rule above, naming under-expression; then how much of each tier's
// expression every method reproduces and how its identity drift compares with the ground truth's.
std::vector<std::string> Verdict(const Aggregate& aggregate);

}  // namespace icef::eval
