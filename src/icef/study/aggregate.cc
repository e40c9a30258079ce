#include "icef/study/aggregate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <sstream>
#include <string_view>
#include <tuple>

#include "icef/model/method.h"
#include "icef/study/report_internal.h"

namespace icef::eval {

std::string RunId::Name() const {
  return "id" + std::to_string(identity_seed) + "_k" + std::to_string(k) + "_" + method +
         (replicate > 0 ? "_r" + std::to_string(replicate) : std::string());
}

namespace {

// Every metric of the report, in table order: its metrics.json key, its axis label, the printf
// format of its values and its direction.
struct MetricInfo {
  Metric metric;
  const char* name;
  const char* label;
  const char* format;
  bool higher_is_better;
};
constexpr std::array<MetricInfo, kNumMetrics> kMetrics = {{
    {Metric::kPsnr, "psnr", "PSNR, dB (higher = better)", "%.2f", true},
    {Metric::kPsnrNeutralFloor, "psnr_neutral_floor",
     "PSNR of the ground-truth neutral, dB (a face that does not move)", "%.2f", false},
    {Metric::kSsim, "ssim", "SSIM (higher = better)", "%.3f", true},
    {Metric::kLpips, "lpips", "LPIPS (lower = better)", "%.3f", false},
    {Metric::kExprGain, "expr_gain", "share of the true expression change reproduced (1 = all, 0 = none)",
     "%.3f", true},
    {Metric::kExprCorr, "expr_corr", "cosine of the render's change with the true change (higher = better)",
     "%.3f", true},
    {Metric::kExprGainCoarse, "expr_gain_coarse",
     "share of the expression change reproduced, low-passed 2 px at 128 (1 = all)", "%.3f", true},
    {Metric::kRegionPsnr, "region_psnr", "PSNR in the brow/eye/mouth region, dB (higher = better)", "%.2f",
     true},
    {Metric::kIdCosine, "id_cosine", "identity cosine to own neutral render (higher = better)", "%.4f", true},
    {Metric::kIdDistance, "id_distance", "identity distance to own neutral render", "%.3f", false},
    {Metric::kIdDistanceGt, "id_distance_gt", "identity distance to ground truth (lower = better)", "%.3f",
     false},
    {Metric::kIdShareUnder06, "id_share_under_0_6", "share of renders under 0.6 from own neutral", "%.2f",
     true},
    {Metric::kIdDistanceReference, "id_distance_reference",
     "ground truth's own distance to its neutral (reference)", "%.3f", false},
    {Metric::kIdExcess, "id_excess",
     "drift beyond the ground truth's own (0 = as the truth; < 0 = under-expression)", "%+.3f", false},
}};

const MetricInfo& Info(Metric m) {
  for (const MetricInfo& info : kMetrics)
    if (info.metric == m) return info;
  ICEF_CHECK(false, "a metric without an entry in kMetrics");
  return kMetrics[0];
}

}  // namespace

const std::array<Metric, kNumMetrics>& AllMetrics() {
  static const std::array<Metric, kNumMetrics> kAll = [] {
    std::array<Metric, kNumMetrics> all{};
    for (int i = 0; i < kNumMetrics; ++i) all[i] = kMetrics[i].metric;
    return all;
  }();
  return kAll;
}

const char* MetricName(Metric m) { return Info(m).name; }
const char* MetricLabel(Metric m) { return Info(m).label; }
const char* MetricFormat(Metric m) { return Info(m).format; }
bool HigherIsBetter(Metric m) { return Info(m).higher_is_better; }

std::optional<double> TierValue(const TierMetrics& t, Metric m) {
  if (m == Metric::kIdShareUnder06) return t.id_share_under_0_6;
  for (const MetricField& f : MetricFields())
    if (std::string_view(f.key) == MetricName(m)) return t.*f.tier;
  ICEF_CHECK(false, std::string("metric ") + MetricName(m) + " has no field in MetricFields()");
  return std::nullopt;
}

std::optional<Spread> Spread::Of(const std::vector<double>& values) {
  if (values.empty()) return std::nullopt;
  Spread s;
  s.n = static_cast<int>(values.size());
  double sum = 0;
  s.min = s.max = values[0];
  for (double v : values) sum += v, s.min = std::min(s.min, v), s.max = std::max(s.max, v);
  s.mean = sum / s.n;
  if (s.n > 1) {
    double ss = 0;
    for (double v : values) ss += (v - s.mean) * (v - s.mean);
    s.std = std::sqrt(ss / (s.n - 1));
  }
  return s;
}

Json Spread::ToJson() const {
  return Json{{"n", n}, {"mean", mean}, {"std", std}, {"min", min}, {"max", max}};
}

Json Comparison::ToJson() const {
  return Json{{"k", k},
              {"other", other},
              {"metric", MetricName(metric)},
              {"icef_mean", icef_mean},
              {"other_mean", other_mean},
              {"icef_better", icef_better},
              {"paired_identities", paired},
              {"icef_wins", icef_wins}};
}

const AggregateCell* Aggregate::Find(int k, const std::string& method, Tier tier) const {
  for (const AggregateCell& c : cells)
    if (c.k == k && c.method == method && c.tier == tier) return &c;
  return nullptr;
}

const TrainFitCell* Aggregate::FindTrainFit(int k, const std::string& method) const {
  for (const TrainFitCell& c : train_fit)
    if (c.k == k && c.method == method) return &c;
  return nullptr;
}

Json TrainFitCell::ToJson() const {
  auto spread = [](const std::optional<Spread>& v) { return v ? v->ToJson() : Json(nullptr); };
  return Json{{"k", k},
              {"method", method},
              {"runs", runs},
              {"face_psnr", spread(face_psnr)},
              {"face_psnr_min", spread(face_psnr_min)},
              {"psnr", spread(psnr)}};
}

namespace {

int MethodOrder(const std::string& name) {
  const auto& all = AllMethods();
  for (size_t i = 0; i < all.size(); ++i)
    if (name == MethodName(all[i])) return static_cast<int>(i);
  return static_cast<int>(all.size());
}

}  // namespace

bool MethodLess(const std::string& a, const std::string& b) {
  const int oa = MethodOrder(a), ob = MethodOrder(b);
  return oa != ob ? oa < ob : a < b;
}

std::string Pm(const std::optional<Spread>& s, const char* format) {
  if (!s) return "-";
  char m[32], d[32], lo[32], hi[32];
  std::snprintf(m, sizeof m, format, s->mean);
  if (s->n == 1) return m;
  std::snprintf(d, sizeof d, format, s->std);
  std::snprintf(lo, sizeof lo, format, s->min);
  std::snprintf(hi, sizeof hi, format, s->max);
  return std::string(m) + " ± " + d + " [" + lo + ", " + hi + "]";
}

const std::vector<std::string>& Baselines() {
  static const std::vector<std::string> kBaselines = {"warp", "nerface"};
  return kBaselines;
}

// The methods the report judges against all others: the paper's method and ICEF on the face-model prior.
const std::vector<std::string>& PrimaryMethods() {
  static const std::vector<std::string> kPrimary = {"icef", "icef-prior"};
  return kPrimary;
}

// The mean of JSON objects of the same shape: floating-point numbers averaged over the objects
// that have one (null when none has), every other value (integer counts, strings) from the first.

namespace {

Json MeanJson(const std::vector<Json>& objects) {
  Json out = objects.front();
  for (auto& [key, value] : out.items()) {
    bool floating = value.is_number_float();
    double sum = 0;
    int n = 0;
    for (const Json& o : objects) {
      const auto it = o.find(key);
      if (it == o.end() || !it->is_number()) continue;
      floating = floating || it->is_number_float();
      sum += it->get<double>();
      ++n;
    }
    if (floating || (value.is_null() && n > 0)) value = n > 0 ? Json(sum / n) : Json(nullptr);
  }
  return out;
}

std::vector<ReplicateSpreadCell> ReplicateSpread(const std::vector<RunRecord>& runs) {
  // (k, method) -> identity -> replicates
  std::map<std::pair<int, std::string>, std::map<uint64_t, std::vector<const RunRecord*>>> groups;
  for (const RunRecord& r : runs) groups[{r.id.k, r.id.method}][r.id.identity_seed].push_back(&r);
  std::vector<ReplicateSpreadCell> out;
  for (const auto& [key, identities] : groups)
    for (Tier tier : AllTiers()) {
      ReplicateSpreadCell cell;
      cell.k = key.first;
      cell.method = key.second;
      cell.tier = tier;
      std::vector<double> psnr_ranges, gain_ranges;
      for (const auto& [seed, reps] : identities) {
        if (reps.size() < 2) continue;
        ++cell.identities;
        cell.replicates = std::max(cell.replicates, static_cast<int>(reps.size()));
        for (auto [metric, ranges] :
             {std::pair{Metric::kPsnr, &psnr_ranges}, std::pair{Metric::kExprGain, &gain_ranges}}) {
          std::vector<double> v;
          for (const RunRecord* r : reps)
            if (const auto x = TierValue(r->metrics.tiers[TierIndex(tier)], metric)) v.push_back(*x);
          if (v.size() < 2) continue;
          const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
          ranges->push_back(*hi - *lo);
        }
      }
      if (cell.identities == 0) continue;
      if (const auto s = Spread::Of(psnr_ranges)) cell.psnr_range = s->mean;
      if (const auto s = Spread::Of(gain_ranges)) cell.expr_gain_range = s->mean;
      out.push_back(std::move(cell));
    }
  std::sort(out.begin(), out.end(), [](const ReplicateSpreadCell& x, const ReplicateSpreadCell& y) {
    if (x.k != y.k) return x.k < y.k;
    if (x.method != y.method) return MethodLess(x.method, y.method);
    return TierIndex(x.tier) < TierIndex(y.tier);
  });
  return out;
}

}  // namespace

Json ReplicateSpreadCell::ToJson() const {
  return Json{{"k", k},
              {"method", method},
              {"tier", TierName(tier)},
              {"identities", identities},
              {"replicates", replicates},
              {"psnr_range", psnr_range ? Json(*psnr_range) : Json(nullptr)},
              {"expr_gain_range", expr_gain_range ? Json(*expr_gain_range) : Json(nullptr)}};
}

std::vector<RunRecord> PoolReplicates(const std::vector<RunRecord>& runs) {
  std::vector<RunRecord> out;
  std::map<std::tuple<uint64_t, int, std::string>, std::vector<const RunRecord*>> groups;
  std::vector<std::tuple<uint64_t, int, std::string>> order;
  for (const RunRecord& r : runs) {
    const auto key = std::make_tuple(r.id.identity_seed, r.id.k, r.id.method);
    auto& g = groups[key];
    if (g.empty()) order.push_back(key);
    g.push_back(&r);
  }
  for (const auto& key : order) {
    const std::vector<const RunRecord*>& g = groups[key];
    RunRecord pooled = *g.front();
    pooled.id.replicate = 0;
    if (g.size() > 1) {
      for (int t = 0; t < kNumTiers; ++t) {
        std::vector<Json> tiers;
        for (const RunRecord* r : g) tiers.push_back(r->metrics.tiers[t].ToJson());
        pooled.metrics.tiers[t] = TierMetrics::FromJson(MeanJson(tiers), "pooled tier").value();
      }
      std::vector<Json> fits;
      for (const RunRecord* r : g) fits.push_back(r->metrics.train_fit.ToJson());
      pooled.metrics.train_fit = TrainingFit::FromJson(MeanJson(fits), "pooled training-view fit").value();
      double train = 0, eval = 0;
      for (const RunRecord* r : g) train += r->train_seconds, eval += r->eval_seconds;
      pooled.train_seconds = train / g.size();
      pooled.eval_seconds = eval / g.size();
    }
    out.push_back(std::move(pooled));
  }
  return out;
}

namespace {

// (k, method) -> runs in identity order.
using RunsByCell = std::map<std::pair<int, std::string>, std::vector<const RunRecord*>>;

RunsByCell GroupRuns(const std::vector<RunRecord>& runs) {
  RunsByCell by_cell;
  for (const RunRecord& r : runs) by_cell[{r.id.k, r.id.method}].push_back(&r);
  for (auto& [key, list] : by_cell)
    std::sort(list.begin(), list.end(), [](const RunRecord* x, const RunRecord* y) {
      return x->id.identity_seed < y->id.identity_seed;
    });
  return by_cell;
}

// The spreads of one (K, method, tier) over its runs.
AggregateCell TierCell(int k, const std::string& method, Tier tier,
                       const std::vector<const RunRecord*>& runs) {
  AggregateCell cell;
  cell.k = k;
  cell.method = method;
  cell.tier = tier;
  std::vector<double> deltas;
  std::array<std::vector<double>, kNumMetrics> values;
  for (const RunRecord* r : runs) {
    const TierMetrics& t = r->metrics.tiers[TierIndex(tier)];
    if (t.count == 0) continue;
    ++cell.runs;
    cell.frames += t.count;
    deltas.push_back(t.mean_delta);
    for (Metric m : AllMetrics())
      if (const std::optional<double> v = TierValue(t, m)) values[static_cast<int>(m)].push_back(*v);
  }
  cell.delta = Spread::Of(deltas);
  for (int m = 0; m < kNumMetrics; ++m) cell.metrics[m] = Spread::Of(values[m]);
  return cell;
}

TrainFitCell FitCell(int k, const std::string& method, const std::vector<const RunRecord*>& runs) {
  TrainFitCell cell;
  cell.k = k;
  cell.method = method;
  std::vector<double> face, face_min, psnr;
  for (const RunRecord* r : runs) {
    const TrainingFit& fit = r->metrics.train_fit;
    if (fit.count > 0) ++cell.runs;
    if (fit.face_psnr) face.push_back(*fit.face_psnr);
    if (fit.face_psnr_min) face_min.push_back(*fit.face_psnr_min);
    if (fit.psnr) psnr.push_back(*fit.psnr);
  }
  cell.face_psnr = Spread::Of(face);
  cell.face_psnr_min = Spread::Of(face_min);
  cell.psnr = Spread::Of(psnr);
  return cell;
}

// Far tier, icef against `other` at K on metric m: the means and the paired wins per identity.
std::optional<Comparison> FarComparison(const Aggregate& a, int k, const std::string& other, Metric m,
                                        const std::vector<const RunRecord*>& icef_runs,
                                        const std::vector<const RunRecord*>& other_runs) {
  const AggregateCell* ci = a.Find(k, "icef", Tier::kFar);
  const AggregateCell* co = a.Find(k, other, Tier::kFar);
  if (!ci || !co || !ci->Get(m) || !co->Get(m)) return std::nullopt;
  Comparison c;
  c.k = k;
  c.other = other;
  c.metric = m;
  c.icef_mean = ci->Get(m)->mean;
  c.other_mean = co->Get(m)->mean;
  c.icef_better = HigherIsBetter(m) ? c.icef_mean > c.other_mean : c.icef_mean < c.other_mean;
  for (const RunRecord* ri : icef_runs)
    for (const RunRecord* ro : other_runs) {
      if (ri->id.identity_seed != ro->id.identity_seed) continue;
      const auto vi = TierValue(ri->metrics.tiers[TierIndex(Tier::kFar)], m);
      const auto vo = TierValue(ro->metrics.tiers[TierIndex(Tier::kFar)], m);
      if (!vi || !vo) continue;
      ++c.paired;
      if (HigherIsBetter(m) ? *vi > *vo : *vi < *vo) ++c.icef_wins;
    }
  return c;
}

// Far tier: icef against every other method, per K, on PSNR and identity similarity.
std::vector<Comparison> FarComparisons(const Aggregate& a, const RunsByCell& by_cell) {
  std::vector<Comparison> out;
  const Metric compared[] = {Metric::kPsnr, Metric::kIdDistance, Metric::kIdCosine};
  for (int k : a.ks) {
    const auto icef_runs = by_cell.find({k, "icef"});
    if (icef_runs == by_cell.end()) continue;
    for (const std::string& other : a.methods) {
      const auto other_runs = by_cell.find({k, other});
      if (other == "icef" || other_runs == by_cell.end()) continue;
      for (Metric m : compared)
        if (auto c = FarComparison(a, k, other, m, icef_runs->second, other_runs->second)) out.push_back(*c);
    }
  }
  return out;
}

}  // namespace

Aggregate AggregateRuns(const std::vector<RunRecord>& all_runs) {
  const std::vector<RunRecord> runs = PoolReplicates(all_runs);
  Aggregate a;
  a.replicate_spread = ReplicateSpread(all_runs);
  std::set<int> ks;
  std::set<uint64_t> ids;
  for (const RunRecord& r : runs) {
    ks.insert(r.id.k);
    ids.insert(r.id.identity_seed);
    if (std::find(a.methods.begin(), a.methods.end(), r.id.method) == a.methods.end())
      a.methods.push_back(r.id.method);
  }
  std::sort(a.methods.begin(), a.methods.end(), MethodLess);
  a.ks.assign(ks.begin(), ks.end());
  a.identities.assign(ids.begin(), ids.end());

  const RunsByCell by_cell = GroupRuns(runs);
  for (int k : a.ks)
    for (const std::string& method : a.methods) {
      const auto it = by_cell.find({k, method});
      if (it == by_cell.end()) continue;
      for (Tier tier : AllTiers()) a.cells.push_back(TierCell(k, method, tier, it->second));
    }
  for (int k : a.ks)
    for (const std::string& method : a.methods)
      if (const auto it = by_cell.find({k, method}); it != by_cell.end())
        a.train_fit.push_back(FitCell(k, method, it->second));
  a.far_comparisons = FarComparisons(a, by_cell);
  for (const std::string& primary : PrimaryMethods())
    for (Tier tier : {Tier::kNear, Tier::kModerate, Tier::kFar})
      for (int k : a.ks) {
        if (!by_cell.count({k, primary})) continue;
        for (const std::string& other : a.methods)
          if (other != primary && by_cell.count({k, other}))
            a.verdicts.push_back(ComparePair(a, k, tier, primary, other));
      }
  return a;
}

}  // namespace icef::eval
