#include "icef/eval/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "icef/core/progress.h"
#include "icef/eval/report_latex.h"
#include "icef/eval/training_view_sheet.h"
#include "icef/io/atomic_file.h"
#include "icef/model/method.h"

namespace fs = std::filesystem;

namespace icef::eval {

std::string RunId::Name() const {
  return "id" + std::to_string(identity_seed) + "_k" + std::to_string(k) + "_" + method +
         (replicate > 0 ? "_r" + std::to_string(replicate) : std::string());
}

const std::array<Metric, kNumMetrics>& AllMetrics() {
  static const std::array<Metric, kNumMetrics> kAll = {
      Metric::kPsnr,          Metric::kPsnrNeutralFloor, Metric::kSsim,          Metric::kLpips,
      Metric::kExprGain,      Metric::kExprCorr,         Metric::kExprGainCoarse, Metric::kRegionPsnr,
      Metric::kIdCosine,
      Metric::kIdDistance,    Metric::kIdDistanceGt,     Metric::kIdShareUnder06, Metric::kIdDistanceReference,
      Metric::kIdExcess};
  return kAll;
}

const char* MetricName(Metric m) {
  switch (m) {
    case Metric::kPsnr: return "psnr";
    case Metric::kPsnrNeutralFloor: return "psnr_neutral_floor";
    case Metric::kSsim: return "ssim";
    case Metric::kLpips: return "lpips";
    case Metric::kExprGain: return "expr_gain";
    case Metric::kExprCorr: return "expr_corr";
    case Metric::kExprGainCoarse: return "expr_gain_coarse";
    case Metric::kRegionPsnr: return "region_psnr";
    case Metric::kIdCosine: return "id_cosine";
    case Metric::kIdDistance: return "id_distance";
    case Metric::kIdDistanceGt: return "id_distance_gt";
    case Metric::kIdShareUnder06: return "id_share_under_0_6";
    case Metric::kIdDistanceReference: return "id_distance_reference";
    case Metric::kIdExcess: return "id_excess";
  }
  return "?";
}

const char* MetricLabel(Metric m) {
  switch (m) {
    case Metric::kPsnr: return "PSNR, dB (higher = better)";
    case Metric::kPsnrNeutralFloor: return "PSNR of the ground-truth neutral, dB (a face that does not move)";
    case Metric::kSsim: return "SSIM (higher = better)";
    case Metric::kLpips: return "LPIPS (lower = better)";
    case Metric::kExprGain: return "share of the true expression change reproduced (1 = all, 0 = none)";
    case Metric::kExprCorr: return "cosine of the render's change with the true change (higher = better)";
    case Metric::kExprGainCoarse: return "share of the expression change reproduced, low-passed 2 px at 128 (1 = all)";
    case Metric::kRegionPsnr: return "PSNR in the brow/eye/mouth region, dB (higher = better)";
    case Metric::kIdCosine: return "identity cosine to own neutral render (higher = better)";
    case Metric::kIdDistance: return "identity distance to own neutral render";
    case Metric::kIdDistanceGt: return "identity distance to ground truth (lower = better)";
    case Metric::kIdShareUnder06: return "share of renders under 0.6 from own neutral";
    case Metric::kIdDistanceReference: return "ground truth's own distance to its neutral (reference)";
    case Metric::kIdExcess: return "drift beyond the ground truth's own (0 = as the truth; < 0 = under-expression)";
  }
  return "?";
}

const char* MetricFormat(Metric m) {
  switch (m) {
    case Metric::kPsnr:
      return "%.2f";
    case Metric::kPsnrNeutralFloor:
      return "%.2f";
    case Metric::kRegionPsnr:
      return "%.2f";
    case Metric::kIdExcess:
      return "%+.3f";
    case Metric::kIdShareUnder06:
      return "%.2f";
    case Metric::kIdCosine:
      return "%.4f";
    default:
      return "%.3f";
  }
}

bool HigherIsBetter(Metric m) {
  return m == Metric::kPsnr || m == Metric::kSsim || m == Metric::kIdCosine || m == Metric::kIdShareUnder06 ||
         m == Metric::kExprGain || m == Metric::kExprCorr || m == Metric::kExprGainCoarse || m == Metric::kRegionPsnr;
}

std::optional<double> TierValue(const TierMetrics& t, Metric m) {
  switch (m) {
    case Metric::kPsnr: return t.psnr;
    case Metric::kPsnrNeutralFloor: return t.psnr_neutral_floor;
    case Metric::kSsim: return t.ssim;
    case Metric::kLpips: return t.lpips;
    case Metric::kExprGain: return t.expr_gain;
    case Metric::kExprCorr: return t.expr_corr;
    case Metric::kExprGainCoarse: return t.expr_gain_coarse;
    case Metric::kRegionPsnr: return t.region_psnr;
    case Metric::kIdCosine: return t.id_cosine;
    case Metric::kIdDistance: return t.id_distance;
    case Metric::kIdDistanceGt: return t.id_distance_gt;
    case Metric::kIdShareUnder06: return t.id_share_under_0_6;
    case Metric::kIdDistanceReference: return t.id_distance_reference;
    case Metric::kIdExcess: return t.id_excess;
  }
  return std::nullopt;
}

const char* OutcomeName(Outcome o) {
  switch (o) {
    case Outcome::kBetter: return "better";
    case Outcome::kUnderExpresses: return "under-expresses";
    case Outcome::kWorseIdentity: return "not better on identity";
    case Outcome::kWorsePsnr: return "not better on PSNR";
    case Outcome::kNoData: return "no data";
  }
  return "?";
}

Json PairVerdict::ToJson() const {
  return Json{{"k", k}, {"tier", TierName(tier)}, {"method", method}, {"other", other}, {"outcome", OutcomeName(outcome)}};
}

PairVerdict ComparePair(const Aggregate& a, int k, Tier tier, const std::string& method, const std::string& other) {
  PairVerdict v;
  v.k = k, v.tier = tier, v.method = method, v.other = other;
  const AggregateCell* ca = a.Find(k, method, tier);
  const AggregateCell* cb = a.Find(k, other, tier);
  if (!ca || !cb) return v;
  const auto ga = ca->Get(Metric::kExprGain), gb = cb->Get(Metric::kExprGain);
  const auto ia = ca->Get(Metric::kIdDistanceGt), ib = cb->Get(Metric::kIdDistanceGt);
  const auto pa = ca->Get(Metric::kPsnr), pb = cb->Get(Metric::kPsnr);
  if (!ga || !gb || !pa || !pb) return v;
  const double tolerance = std::max({ga->std, gb->std, kGainTolerance});
  if (ga->mean < kMinExpressionGain || ga->mean < gb->mean - tolerance) {
    v.outcome = Outcome::kUnderExpresses;
  } else if (ia && ib && !(ia->mean < ib->mean)) {
    v.outcome = Outcome::kWorseIdentity;
  } else if (!(pa->mean > pb->mean)) {
    v.outcome = Outcome::kWorsePsnr;
  } else {
    v.outcome = Outcome::kBetter;
  }
  return v;
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

Json Spread::ToJson() const { return Json{{"n", n}, {"mean", mean}, {"std", std}, {"min", min}, {"max", max}}; }

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

bool ReportContext::PerIdentity() const { return per_identity || identity_role.rfind("validation", 0) == 0; }

namespace {

int MethodOrder(const std::string& name) {
  const auto& all = AllMethods();
  for (size_t i = 0; i < all.size(); ++i)
    if (name == MethodName(all[i])) return static_cast<int>(i);
  return static_cast<int>(all.size());
}

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

Aggregate AggregateRuns(const std::vector<RunRecord>& all_runs) {
  const std::vector<RunRecord> runs = PoolReplicates(all_runs);
  Aggregate a;
  a.replicate_spread = ReplicateSpread(all_runs);
  std::set<int> ks;
  std::set<uint64_t> ids;
  std::vector<std::string> methods;
  for (const RunRecord& r : runs) {
    ks.insert(r.id.k);
    ids.insert(r.id.identity_seed);
    if (std::find(methods.begin(), methods.end(), r.id.method) == methods.end()) methods.push_back(r.id.method);
  }
  std::sort(methods.begin(), methods.end(), MethodLess);
  a.ks.assign(ks.begin(), ks.end());
  a.identities.assign(ids.begin(), ids.end());
  a.methods = methods;

  // (k, method) -> runs in identity order.
  std::map<std::pair<int, std::string>, std::vector<const RunRecord*>> by_cell;
  for (const RunRecord& r : runs) by_cell[{r.id.k, r.id.method}].push_back(&r);
  for (auto& [key, list] : by_cell)
    std::sort(list.begin(), list.end(),
              [](const RunRecord* x, const RunRecord* y) { return x->id.identity_seed < y->id.identity_seed; });

  for (int k : a.ks)
    for (const std::string& method : a.methods) {
      const auto it = by_cell.find({k, method});
      if (it == by_cell.end()) continue;
      for (Tier tier : AllTiers()) {
        AggregateCell cell;
        cell.k = k;
        cell.method = method;
        cell.tier = tier;
        std::vector<double> deltas;
        std::array<std::vector<double>, kNumMetrics> values;
        for (const RunRecord* r : it->second) {
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
        a.cells.push_back(std::move(cell));
      }
    }

  for (int k : a.ks)
    for (const std::string& method : a.methods) {
      const auto it = by_cell.find({k, method});
      if (it == by_cell.end()) continue;
      TrainFitCell cell;
      cell.k = k;
      cell.method = method;
      std::vector<double> face, face_min, psnr;
      for (const RunRecord* r : it->second) {
        const TrainingFit& fit = r->metrics.train_fit;
        if (fit.count > 0) ++cell.runs;
        if (fit.face_psnr) face.push_back(*fit.face_psnr);
        if (fit.face_psnr_min) face_min.push_back(*fit.face_psnr_min);
        if (fit.psnr) psnr.push_back(*fit.psnr);
      }
      cell.face_psnr = Spread::Of(face);
      cell.face_psnr_min = Spread::Of(face_min);
      cell.psnr = Spread::Of(psnr);
      a.train_fit.push_back(std::move(cell));
    }

  // Far tier: icef against every other method, per K, on PSNR and identity similarity.
  const Metric compared[] = {Metric::kPsnr, Metric::kIdDistance, Metric::kIdCosine};
  for (int k : a.ks) {
    const auto icef_runs = by_cell.find({k, "icef"});
    if (icef_runs == by_cell.end()) continue;
    for (const std::string& other : a.methods) {
      if (other == "icef") continue;
      const auto other_runs = by_cell.find({k, other});
      if (other_runs == by_cell.end()) continue;
      for (Metric m : compared) {
        const AggregateCell* ci = a.Find(k, "icef", Tier::kFar);
        const AggregateCell* co = a.Find(k, other, Tier::kFar);
        if (!ci || !co || !ci->Get(m) || !co->Get(m)) continue;
        Comparison c;
        c.k = k;
        c.other = other;
        c.metric = m;
        c.icef_mean = ci->Get(m)->mean;
        c.other_mean = co->Get(m)->mean;
        c.icef_better = HigherIsBetter(m) ? c.icef_mean > c.other_mean : c.icef_mean < c.other_mean;
        for (const RunRecord* ri : icef_runs->second)
          for (const RunRecord* ro : other_runs->second) {
            if (ri->id.identity_seed != ro->id.identity_seed) continue;
            const auto vi = TierValue(ri->metrics.tiers[TierIndex(Tier::kFar)], m);
            const auto vo = TierValue(ro->metrics.tiers[TierIndex(Tier::kFar)], m);
            if (!vi || !vo) continue;
            ++c.paired;
            if (HigherIsBetter(m) ? *vi > *vo : *vi < *vo) ++c.icef_wins;
          }
        a.far_comparisons.push_back(c);
      }
    }
  }
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

std::vector<std::string> Verdict(const Aggregate& a) {
  std::vector<std::string> lines;
  std::vector<std::string> baselines;
  for (const std::string& b : Baselines())
    if (std::find(a.methods.begin(), a.methods.end(), b) != a.methods.end()) baselines.push_back(b);
  const bool has_icef = std::find(a.methods.begin(), a.methods.end(), "icef") != a.methods.end();
  if (!has_icef || baselines.empty()) {
    lines.push_back("No verdict: the bench did not run icef together with a baseline (warp, nerface).");
  }
  auto value = [&](int k, const std::string& method, Tier tier, Metric m) {
    const AggregateCell* c = a.Find(k, method, tier);
    return c ? Pm(c->Get(m), MetricFormat(m)) : std::string("-");
  };
  auto pair_detail = [&](const PairVerdict& v) {
    std::string d = "K=" + std::to_string(v.k) + " vs " + v.other + ": " + OutcomeName(v.outcome);
    Metric shown = Metric::kExprGain;
    if (v.outcome == Outcome::kWorseIdentity) shown = Metric::kIdDistanceGt;
    if (v.outcome == Outcome::kWorsePsnr || v.outcome == Outcome::kBetter) shown = Metric::kPsnr;
    if (v.outcome != Outcome::kNoData)
      d += std::string(" (") + MetricName(shown) + " " + value(v.k, v.method, v.tier, shown) + " vs " +
           value(v.k, v.other, v.tier, shown) + ")";
    return d;
  };
  auto tier_line = [&](const std::string& primary, Tier tier, const std::vector<std::string>& others,
                       const std::string& label) {
    int pairs = 0, better = 0;
    std::string detail;
    for (const PairVerdict& v : a.verdicts) {
      if (v.method != primary || v.tier != tier || v.outcome == Outcome::kNoData ||
          std::find(others.begin(), others.end(), v.other) == others.end())
        continue;
      ++pairs;
      better += v.outcome == Outcome::kBetter;
      detail += (detail.empty() ? "" : "; ") + pair_detail(v);
    }
    if (pairs == 0) return;
    std::string head;
    if (better == pairs)
      head = primary + " is **better** in every comparison";
    else if (better == 0)
      head = primary + " is **not better** in any comparison";
    else
      head = primary + " is better in **" + std::to_string(better) + " of " + std::to_string(pairs) + "** comparisons";
    lines.push_back("**" + std::string(TierName(tier)) + " tier, " + primary + " vs " + label + "**: " + head + ". " +
                    detail + ".");
  };
  if (has_icef && !baselines.empty()) {
    std::vector<std::string> ablations;
    for (const std::string& m : a.methods)
      if (m != "icef" && std::find(baselines.begin(), baselines.end(), m) == baselines.end()) ablations.push_back(m);
    for (Tier tier : {Tier::kFar, Tier::kModerate, Tier::kNear}) tier_line("icef", tier, baselines, "the baselines");
    tier_line("icef", Tier::kFar, ablations, "its ablations and the other methods");
  }
  if (std::find(a.methods.begin(), a.methods.end(), "icef-prior") != a.methods.end()) {
    std::vector<std::string> others;
    for (const std::string& m : a.methods)
      if (m != "icef-prior") others.push_back(m);
    for (Tier tier : {Tier::kFar, Tier::kModerate, Tier::kNear})
      tier_line("icef-prior", tier, others, "every other method");
  }
  // How much of the expression each method shows, and its identity drift against the truth's own.
  for (int k : a.ks) {
    std::string gains, drift, under;
    for (const std::string& method : a.methods) {
      std::string g;
      for (Tier tier : {Tier::kNear, Tier::kModerate, Tier::kFar}) {
        const AggregateCell* c = a.Find(k, method, tier);
        char buf[32] = "-";
        if (c && c->Get(Metric::kExprGain)) std::snprintf(buf, sizeof buf, "%.2f", c->Get(Metric::kExprGain)->mean);
        if (!g.empty()) g += "/";
        g += buf;
      }
      if (!gains.empty()) gains += ", ";
      gains += "`" + method + "` " + g;
      const AggregateCell* far = a.Find(k, method, Tier::kFar);
      if (far && far->Get(Metric::kIdExcess)) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "`%s` %+.3f", method.c_str(), far->Get(Metric::kIdExcess)->mean);
        drift += (drift.empty() ? "" : ", ") + std::string(buf);
      }
      if (far && far->Get(Metric::kExprGain) && far->Get(Metric::kExprGain)->mean < 0.5) {
        char buf[128];
        std::snprintf(buf, sizeof buf, "`%s` (%.0f%%)", method.c_str(), 100 * far->Get(Metric::kExprGain)->mean);
        under += (under.empty() ? "" : ", ") + std::string(buf);
      }
    }
    lines.push_back("**Expression reproduced, K=" + std::to_string(k) +
                    "** (expr_gain near/moderate/far, mean over identities; 1 = the full expression, 0 = none): " +
                    gains + "." +
                    (under.empty() ? std::string()
                                   : " **Under-expression** in the far tier (less than half of the expression): " +
                                         under + "."));
    if (!drift.empty())
      lines.push_back("**Identity drift beyond the ground truth's own, K=" + std::to_string(k) +
                      "** (far-tier id_excess = id_distance - id_distance_reference; negative = the render moves "
                      "less than the truth): " + drift + ".");
  }
  return lines;
}

namespace {

std::string Opt(const std::optional<double>& v, const char* format) {
  if (!v) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, format, *v);
  return buf;
}

// One run's row of the per-identity table.
struct IdentityRow {
  const RunRecord* run = nullptr;
  std::optional<double> train_face_psnr, observed_psnr, far_psnr, observed_region_psnr, observed_id_distance_gt,
      far_expr_gain, train_face_psnr_min, train_face_detail;
};

// The rows of every run, by identity, K and method.
std::vector<IdentityRow> IdentityRows(const std::vector<RunRecord>& runs) {
  std::vector<IdentityRow> rows;
  for (const RunRecord& r : runs) {
    const TierMetrics& obs = r.metrics.tiers[TierIndex(Tier::kObserved)];
    const TierMetrics& far = r.metrics.tiers[TierIndex(Tier::kFar)];
    rows.push_back(IdentityRow{&r, r.metrics.train_fit.face_psnr, obs.psnr, far.psnr, obs.region_psnr,
                               obs.id_distance_gt, far.expr_gain, r.metrics.train_fit.face_psnr_min,
                               r.metrics.train_fit.face_detail});
  }
  std::stable_sort(rows.begin(), rows.end(), [](const IdentityRow& x, const IdentityRow& y) {
    const RunId &a = x.run->id, &b = y.run->id;
    if (a.identity_seed != b.identity_seed) return a.identity_seed < b.identity_seed;
    if (a.k != b.k) return a.k < b.k;
    return MethodLess(a.method, b.method);
  });
  return rows;
}

// The identity whose runs have the lowest mean of one value, and its run with the lowest value.
struct WorstIdentity {
  uint64_t seed = 0;
  double mean = 0;
  int runs = 0;                       // its runs with a value
  const RunRecord* worst_run = nullptr;
  double worst_value = 0;
  Json ToJson() const {
    return Json{{"identity_seed", seed}, {"mean", mean}, {"runs", runs}, {"worst_run", worst_run->id.Name()},
                {"worst_value", worst_value}};
  }
};

std::optional<WorstIdentity> FindWorstIdentity(const std::vector<IdentityRow>& rows,
                                               std::optional<double> IdentityRow::*value) {
  std::map<uint64_t, std::pair<double, int>> sums;  // seed -> (sum, count)
  for (const IdentityRow& row : rows)
    if (const std::optional<double>& v = row.*value) {
      auto& [sum, n] = sums[row.run->id.identity_seed];
      sum += *v, ++n;
    }
  std::optional<WorstIdentity> worst;
  for (const auto& [seed, sum_n] : sums) {
    const double mean = sum_n.first / sum_n.second;
    if (!worst || mean < worst->mean) worst = WorstIdentity{seed, mean, sum_n.second};
  }
  if (!worst) return std::nullopt;
  for (const IdentityRow& row : rows) {
    const std::optional<double>& v = row.*value;
    if (row.run->id.identity_seed != worst->seed || !v) continue;
    if (!worst->worst_run || *v < worst->worst_value) worst->worst_run = row.run, worst->worst_value = *v;
  }
  return worst;
}

std::string WorstIdentityLine(const std::optional<WorstIdentity>& w, const std::string& what,
                              const std::map<std::string, std::string>& run_sheets) {
  if (!w) return "**Worst identity by " + what + "**: no values.";
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "**Worst identity by %s**: seed %llu (mean %.2f dB over its %d run%s; lowest run `%s`, %.2f dB).",
                what.c_str(), static_cast<unsigned long long>(w->seed), w->mean, w->runs, w->runs == 1 ? "" : "s",
                w->worst_run->id.Name().c_str(), w->worst_value);
  std::string line = buf;
  const auto sheet = run_sheets.find(w->worst_run->id.Name());
  if (sheet != run_sheets.end())
    line += " Its training views, truth left and render right: [" + sheet->second + "](" + sheet->second + ")";
  return line;
}

// The worst identities of a per-identity report: by training-view face PSNR, then by observed PSNR.
std::array<std::optional<WorstIdentity>, 2> WorstIdentities(const std::vector<IdentityRow>& rows) {
  return {FindWorstIdentity(rows, &IdentityRow::train_face_psnr), FindWorstIdentity(rows, &IdentityRow::observed_psnr)};
}

}  // namespace

std::string ReportMarkdown(const Aggregate& a, const std::vector<RunRecord>& runs, const ReportContext& ctx,
                           const std::vector<std::string>& plots) {
  std::ostringstream s;
  s << "# " << ctx.title << "\n\n";
  s << "Generated by `icef bench` from " << runs.size() << " runs (every number below is computed from the runs' "
    << "`metrics.json` files; `report.json` holds the same numbers).\n\n";
  s << "- identities (seeds): ";
  for (size_t i = 0; i < a.identities.size(); ++i) s << (i ? ", " : "") << a.identities[i];
  if (!ctx.identity_role.empty()) s << " (" << ctx.identity_role << ")";
  s << "\n";
  if (ctx.tier_thresholds) {
    char t[160];
    std::snprintf(t, sizeof t, "- tiers by delta: observed = 0, near (0, %.2f], moderate (%.2f, %.2f], far > %.2f\n",
                  (*ctx.tier_thresholds)[0], (*ctx.tier_thresholds)[0], (*ctx.tier_thresholds)[1],
                  (*ctx.tier_thresholds)[1]);
    s << t;
  }
  s << "- K (training frames): ";
  for (size_t i = 0; i < a.ks.size(); ++i) s << (i ? ", " : "") << a.ks[i];
  s << "\n- methods: ";
  for (size_t i = 0; i < a.methods.size(); ++i) s << (i ? ", " : "") << "`" << a.methods[i] << "`";
  s << "\n";
  if (ctx.wall_seconds > 0) s << "- bench wall time: " << ProgressBar::FormatDuration(ctx.wall_seconds) << "\n";
  double train_total = 0;
  int64_t steps_min = -1, steps_max = -1;
  for (const RunRecord& r : runs) {
    train_total += r.train_seconds;
    steps_min = steps_min < 0 ? r.train_steps : std::min(steps_min, r.train_steps);
    steps_max = std::max(steps_max, r.train_steps);
  }
  if (!runs.empty()) {
    s << "- training: " << (steps_min == steps_max ? std::to_string(steps_min) : std::to_string(steps_min) + "-" + std::to_string(steps_max))
      << " steps per run, " << ProgressBar::FormatDuration(train_total) << " of training in all ("
      << ProgressBar::FormatDuration(train_total / runs.size()) << " per run on average)\n";
  }
  if (!ctx.settings.empty()) s << "- settings: `" << ctx.settings.dump() << "`\n";
  char rule[512];
  std::snprintf(rule, sizeof rule,
                "Rule: a method is better than another in a tier only where it reproduces at least %.0f%% of the "
                "expression (expr_gain), its expr_gain is not lower than the other's beyond the spread over identities "
                "(the larger sample std, at least %.2f), and it is better on both id_distance_gt and PSNR. A face "
                "that does not move never wins.",
                100 * kMinExpressionGain, kGainTolerance);
  s << "\n## Verdict (computed)\n\n" << rule << "\n\n";
  for (const std::string& line : Verdict(a)) s << "- " << line << "\n";
  s << "\n## Methods and caveats\n\n"
    << "- `icef`: deformation + static canonical field + L_id + L_smooth + confidence-weighted warping; "
    << "`icef-no-id` (no L_id, no L_smooth), `icef-no-conf` (kappa = 1) and `icef-uniform` (L_id with M = 0 "
    << "everywhere: deformation damped everywhere, not only outside the landmark regions) are its ablations.\n"
    << "- Expression fidelity: `expr_gain` is the share of the true change (ground truth - ground-truth neutral) "
    << "that the render's change (render - the model's own neutral render, same view) reproduces inside the "
    << "brow/eye/mouth region (1 = all, 0 = none), `expr_corr` their cosine, `region_psnr` the PSNR there; "
    << "`psnr_neutral_floor` is the PSNR a model that renders no expression would score (the ground-truth "
    << "neutral against the ground truth). `id_excess` = `id_distance` - `id_distance_reference`: identity "
    << "drift beyond what the expression itself causes (negative = under-expression).\n"
    << "- Baselines are stand-ins built on the same engine: `warp` (a single learned warp, no identity losses, "
    << "no confidence) stands in for FDNeRF-style deformation methods, `nerface` (expression concatenated into "
    << "the radiance field, no warp) for NeRFFaceEditing/NerFace-style entangled methods. **FDNeRF and "
    << "NeRFFaceEditing proper are not available here and were not run.**\n"
    << "- Identity: dlib's ResNet face descriptor; `id_distance` / `id_cosine` compare a render with the model's "
    << "own neutral (expression zero) render of the same view (the paper's drift measure); `id_distance_gt` "
    << "compares it with the ground-truth image; `id_distance_reference` is the same measure on the ground truth "
    << "(ground-truth frame vs ground-truth neutral, same chips), i.e. the drift a perfect model would show. "
    << "0.6 is the network's same-person threshold. For scale: "
    << "different real people have a median cosine of about 0.84 on this network, the same person 0.93-0.99.\n"
    << "- Training-view fit: every training frame rendered back at its own camera and expression; `face_psnr` "
    << "is the PSNR inside the hull of its 68 landmarks (the run's mean over its views; `face_psnr_min` its worst "
    << "view), `psnr` over the full image. A model that cannot reproduce its own training views is underfitting, "
    << "whatever its batch PSNR says.\n";
  bool lpips = false;
  for (const RunRecord& r : runs) lpips = lpips || r.metrics.lpips_available;
  if (!lpips) s << "- LPIPS: unavailable (no weights file given), reported as `-` / null.\n";
  int id_missing = 0, frames = 0;
  bool id_unavailable = false;
  for (const RunRecord& r : runs) {
    id_missing += r.metrics.identity_missing;
    frames += static_cast<int>(r.metrics.frames.size());
    id_unavailable = id_unavailable || !r.metrics.identity_available;
  }
  if (id_unavailable) s << "- Identity metrics unavailable in some runs (face-identity model not installed).\n";
  if (id_missing > 0)
    s << "- No face could be aligned in " << id_missing << " of " << frames
      << " evaluated frames; their identity metrics are null and left out of the means.\n";
  for (const std::string& n : ctx.notes) s << "- " << n << "\n";

  s << "\n## Results\n\nCells: mean ± sample std [min, max] over identities of the per-run tier means; "
    << "`runs` = identities contributing, `delta` = mean expression distance of the tier's frames.\n";
  const std::vector<Metric> image_metrics = {Metric::kPsnr,     Metric::kPsnrNeutralFloor, Metric::kSsim,
                                             Metric::kLpips,    Metric::kExprGain,         Metric::kExprCorr,
                                             Metric::kExprGainCoarse, Metric::kRegionPsnr};
  const std::vector<Metric> identity_metrics = {Metric::kIdDistanceGt, Metric::kIdDistance, Metric::kIdDistanceReference,
                                                Metric::kIdExcess,     Metric::kIdCosine,   Metric::kIdShareUnder06};
  for (int k : a.ks) {
    for (const auto& [title, metrics] : {std::pair{"image and expression", &image_metrics},
                                         std::pair{"identity", &identity_metrics}}) {
      s << "\n### K = " << k << ", " << title << "\n\n| tier | method | runs | delta |";
      for (Metric m : *metrics) s << " " << MetricName(m) << " |";
      s << "\n|---|---|---|---|";
      for (size_t i = 0; i < metrics->size(); ++i) s << "---|";
      s << "\n";
      for (Tier tier : AllTiers())
        for (const std::string& method : a.methods) {
          const AggregateCell* c = a.Find(k, method, tier);
          if (!c || c->runs == 0) continue;
          char d[32];
          std::snprintf(d, sizeof d, "%.2f", c->delta ? c->delta->mean : 0.0);
          s << "| " << TierName(tier) << " | `" << method << "` | " << c->runs << " | " << d << " |";
          for (Metric m : *metrics) s << " " << Pm(c->Get(m), MetricFormat(m)) << " |";
          s << "\n";
        }
    }
    std::string fit_rows;
    for (const std::string& method : a.methods) {
      const TrainFitCell* c = a.FindTrainFit(k, method);
      if (!c || c->runs == 0) continue;
      fit_rows += "| `" + method + "` | " + std::to_string(c->runs) + " | " + Pm(c->face_psnr, "%.2f") + " | " +
                  Pm(c->face_psnr_min, "%.2f") + " | " + Pm(c->psnr, "%.2f") + " |\n";
    }
    if (!fit_rows.empty())
      s << "\n### K = " << k << ", training-view fit\n\n| method | runs | face_psnr | face_psnr_min | psnr |\n"
        << "|---|---|---|---|---|\n" << fit_rows;
  }
  if (!a.replicate_spread.empty()) {
    s << "\n## Training-seed spread\n\nIdentities trained more than once (`--replicates`), each time with its own "
      << "training seed: the tables above count each identity once, as the mean of its replicates; here, the mean "
      << "over those identities of each one's range (max - min over its replicates). A difference between methods "
      << "or settings smaller than this is within what retraining alone changes.\n\n"
      << "| K | method | tier | identities | replicates | psnr range (dB) | expr_gain range |\n"
      << "|---|---|---|---|---|---|---|\n";
    for (const ReplicateSpreadCell& c : a.replicate_spread)
      s << "| " << c.k << " | `" << c.method << "` | " << TierName(c.tier) << " | " << c.identities << " | "
        << c.replicates << " | " << Opt(c.psnr_range, "%.2f") << " | " << Opt(c.expr_gain_range, "%.3f") << " |\n";
  }
  if (ctx.PerIdentity() && !runs.empty()) {
    const std::vector<RunRecord> pooled = PoolReplicates(runs);
    const std::vector<IdentityRow> rows = IdentityRows(pooled);
    s << "\n## Per identity\n\nEvery run (with training replicates, the mean of an identity's replicates): "
      << "the training-view fit (mean face-region PSNR over its training views, "
      << "its worst view, and the face's fine detail relative to the truth's: 1 = as sharp, below 1 = blurred) "
      << "beside its observed- and far-tier numbers, to find the identity that fails and see whether it already "
      << "fails on its own training views.\n\n"
      << "| identity | method | K | train face_psnr | worst view | face detail | observed psnr | far psnr | "
      << "observed region_psnr | observed id_distance_gt | far expr_gain |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const IdentityRow& row : rows)
      s << "| " << row.run->id.identity_seed << " | `" << row.run->id.method << "` | " << row.run->id.k << " | "
        << Opt(row.train_face_psnr, "%.2f") << " | " << Opt(row.train_face_psnr_min, "%.2f") << " | "
        << Opt(row.train_face_detail, "%.2f") << " | " << Opt(row.observed_psnr, "%.2f") << " | "
        << Opt(row.far_psnr, "%.2f") << " | " << Opt(row.observed_region_psnr, "%.2f") << " | "
        << Opt(row.observed_id_distance_gt, "%.3f") << " | " << Opt(row.far_expr_gain, "%.3f") << " |\n";
    const auto [worst_fit, worst_psnr] = WorstIdentities(rows);
    s << "\n- " << WorstIdentityLine(worst_fit, "training-view face PSNR", ctx.run_sheets) << "\n- "
      << WorstIdentityLine(worst_psnr, "observed PSNR", ctx.run_sheets) << "\n";
  }
  if (!plots.empty()) {
    s << "\n## Plots\n\nEach metric against delta (x = mean delta of each tier), one line per method, error bars "
      << "= std over identities; one panel per K. SVG versions beside the PNGs.\n\n";
    for (const std::string& p : plots) s << "![" << p << "](" << p << ")\n\n";
  }
  s << "\n## Runs\n\n| run | steps | train | eval | frames | no face | train face_psnr |\n"
    << "|---|---|---|---|---|---|---|\n";
  for (const RunRecord& r : runs)
    s << "| " << r.id.Name() << " | " << r.train_steps << " | " << ProgressBar::FormatDuration(r.train_seconds)
      << " | " << ProgressBar::FormatDuration(r.eval_seconds) << " | " << r.metrics.frames.size() << " | "
      << r.metrics.identity_missing << " | " << Opt(r.metrics.train_fit.face_psnr, "%.2f") << " |\n";
  return s.str();
}

Json ReportJson(const Aggregate& a, const std::vector<RunRecord>& runs, const ReportContext& ctx) {
  Json j;
  j["title"] = ctx.title;
  j["settings"] = ctx.settings;
  if (ctx.wall_seconds > 0) j["wall_seconds"] = ctx.wall_seconds;
  j["identities"] = a.identities;
  j["ks"] = a.ks;
  j["methods"] = a.methods;
  Json cells = Json::array();
  for (const AggregateCell& c : a.cells) {
    Json cj;
    cj["k"] = c.k;
    cj["method"] = c.method;
    cj["tier"] = TierName(c.tier);
    cj["runs"] = c.runs;
    cj["frames"] = c.frames;
    cj["delta"] = c.delta ? c.delta->ToJson() : Json(nullptr);
    for (Metric m : AllMetrics()) cj[MetricName(m)] = c.Get(m) ? c.Get(m)->ToJson() : Json(nullptr);
    cells.push_back(std::move(cj));
  }
  j["aggregate"] = std::move(cells);
  Json comps = Json::array();
  for (const Comparison& c : a.far_comparisons) comps.push_back(c.ToJson());
  j["far_comparisons"] = std::move(comps);
  Json verdicts = Json::array();
  for (const PairVerdict& v : a.verdicts) verdicts.push_back(v.ToJson());
  j["pair_verdicts"] = std::move(verdicts);
  Json fits = Json::array();
  for (const TrainFitCell& c : a.train_fit) fits.push_back(c.ToJson());
  j["train_fit"] = std::move(fits);
  Json spread = Json::array();
  for (const ReplicateSpreadCell& c : a.replicate_spread) spread.push_back(c.ToJson());
  j["replicate_spread"] = std::move(spread);
  if (ctx.PerIdentity()) {
    const std::vector<RunRecord> pooled = PoolReplicates(runs);
    const std::vector<IdentityRow> rows = IdentityRows(pooled);
    const auto [worst_fit, worst_psnr] = WorstIdentities(rows);
    const auto worst_json = [&](const std::optional<WorstIdentity>& w) {
      if (!w) return Json(nullptr);
      Json out = w->ToJson();
      const auto sheet = ctx.run_sheets.find(w->worst_run->id.Name());
      if (sheet != ctx.run_sheets.end()) out["training_views"] = sheet->second;
      return out;
    };
    j["worst_identity"] = Json{{"train_fit_face_psnr", worst_json(worst_fit)}, {"observed_psnr", worst_json(worst_psnr)}};
  }
  if (!ctx.identity_role.empty()) j["identity_role"] = ctx.identity_role;
  if (ctx.tier_thresholds) j["tier_thresholds"] = *ctx.tier_thresholds;
  j["verdict"] = Verdict(a);
  Json rj = Json::array();
  for (const RunRecord& r : runs)
    rj.push_back(Json{{"name", r.id.Name()},
                      {"identity_seed", r.id.identity_seed},
                      {"replicate", r.id.replicate},
                      {"k", r.id.k},
                      {"method", r.id.method},
                      {"train_steps", r.train_steps},
                      {"train_seconds", r.train_seconds},
                      {"eval_seconds", r.eval_seconds},
                      {"identity_missing", r.metrics.identity_missing},
                      {"train_fit_face_psnr", r.metrics.train_fit.face_psnr ? Json(*r.metrics.train_fit.face_psnr)
                                                                            : Json(nullptr)}});
  j["runs"] = std::move(rj);
  return j;
}

Json RunRecordJson(const RunRecord& r) {
  Json j = r.metrics.ToJson();
  j["run"] = Json{{"identity_seed", r.id.identity_seed}, {"k", r.id.k},
                  {"method", r.id.method},               {"replicate", r.id.replicate},
                  {"train_steps", r.train_steps},
                  {"train_seconds", r.train_seconds},    {"eval_seconds", r.eval_seconds}};
  return j;
}

Result<RunRecord> ReadRunRecord(const fs::path& path) {
  ICEF_ASSIGN_OR_RETURN(const Json j, ReadJsonFile(path));
  RunRecord r;
  ICEF_ASSIGN_OR_RETURN(r.metrics, EvalResult::FromJson(j, path.string()));
  const auto run = j.find("run");
  if (run == j.end() || !run->is_object()) return Status::Error(path.string() + ": run: missing (not a bench run)");
  ICEF_ASSIGN_OR_RETURN(const JsonObjectView v, JsonObjectView::Make(*run, path.string(), "run"));
  ICEF_ASSIGN_OR_RETURN(const double seed, v.Number("identity_seed"));
  if (seed < 0 || seed != std::floor(seed)) return v.Error("identity_seed", "expected a non-negative integer");
  r.id.identity_seed = static_cast<uint64_t>(seed);
  ICEF_ASSIGN_OR_RETURN(r.id.k, v.Int("k"));
  ICEF_ASSIGN_OR_RETURN(r.id.method, v.String("method"));
  if (run->contains("replicate")) {  // absent in runs from before replicates: 0
    ICEF_ASSIGN_OR_RETURN(r.id.replicate, v.Int("replicate"));
    if (r.id.replicate < 0) return v.Error("replicate", "expected a non-negative integer");
  }
  ICEF_ASSIGN_OR_RETURN(const double steps, v.Number("train_steps"));
  r.train_steps = static_cast<int64_t>(steps);
  ICEF_ASSIGN_OR_RETURN(r.train_seconds, v.Number("train_seconds"));
  ICEF_ASSIGN_OR_RETURN(r.eval_seconds, v.Number("eval_seconds"));
  if (r.id.method != r.metrics.method)
    return Status::Error(path.string() + ": run.method '" + r.id.method + "' differs from method '" +
                         r.metrics.method + "'");
  return r;
}

Result<std::vector<RunRecord>> ReadRunRecords(const fs::path& dir) {
  std::vector<RunRecord> out;
  const fs::path runs_dir = dir / "runs";
  std::error_code ec;
  if (!fs::is_directory(runs_dir, ec)) return out;
  std::vector<fs::path> files;
  for (const fs::directory_entry& e : fs::directory_iterator(runs_dir, ec))
    if (e.is_directory() && fs::exists(e.path() / "metrics.json")) files.push_back(e.path() / "metrics.json");
  if (ec) return Status::Error(runs_dir.string() + ": cannot list: " + ec.message());
  for (const fs::path& f : files) {
    ICEF_ASSIGN_OR_RETURN(RunRecord r, ReadRunRecord(f));
    out.push_back(std::move(r));
  }
  std::sort(out.begin(), out.end(), [](const RunRecord& x, const RunRecord& y) {
    if (x.id.identity_seed != y.id.identity_seed) return x.id.identity_seed < y.id.identity_seed;
    if (x.id.k != y.id.k) return x.id.k < y.id.k;
    if (x.id.method != y.id.method) return MethodLess(x.id.method, y.id.method);
    return x.id.replicate < y.id.replicate;
  });
  return out;
}

namespace {

std::string ShellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// The gnuplot commands drawing one metric: one panel per K, one line per method.
std::string PlotCommands(const Aggregate& a, Metric m, const std::string& dat) {
  std::ostringstream s;
  s << "set multiplot layout 1," << a.ks.size() << " title \"" << MetricName(m) << " against delta (mean +- std over "
    << a.identities.size() << " identities)\"\n";
  s << "set xlabel \"delta (distance to the nearest training expression)\"\n";
  s << "set ylabel \"" << MetricLabel(m) << "\"\nset grid\nset key below horizontal box\nset offsets 0.05, 0.05, 0, 0\n";
  for (size_t ki = 0; ki < a.ks.size(); ++ki) {
    s << "set title \"K = " << a.ks[ki] << "\"\nplot ";
    for (size_t mi = 0; mi < a.methods.size(); ++mi) {
      s << (mi ? ", " : "") << "'" << dat << "' index " << ki * a.methods.size() + mi
        << " using 1:2:3 with yerrorlines lw 2 pt 7 title \"" << a.methods[mi] << "\"";
    }
    s << "\n";
  }
  s << "unset multiplot\n";
  return s.str();
}

}  // namespace

bool HaveGnuplot() { return std::system("command -v gnuplot >/dev/null 2>&1") == 0; }

Status RunGnuplot(const fs::path& plot_dir, const std::string& name) {
  const std::string cmd = "cd " + ShellQuote(plot_dir.string()) + " && gnuplot " + ShellQuote(name + ".gp") + " >" +
                          ShellQuote(name + ".log") + " 2>&1";
  if (std::system(cmd.c_str()) != 0)
    return Status::Error((plot_dir / (name + ".gp")).string() + ": gnuplot failed (see " +
                         (plot_dir / (name + ".log")).string() + ")");
  std::error_code ec;
  fs::remove(plot_dir / (name + ".log"), ec);
  return Status::Ok();
}

Result<std::vector<std::string>> WritePlots(const fs::path& dir, const Aggregate& a, std::string* note) {
  std::vector<std::string> pngs;
  if (a.ks.empty() || a.methods.empty()) return pngs;
  const fs::path plot_dir = dir / "plots";
  std::error_code ec;
  fs::create_directories(plot_dir, ec);
  if (ec) return Status::Error(plot_dir.string() + ": cannot create directory: " + ec.message());
  const bool have_gnuplot = HaveGnuplot();
  const int width = 380 * static_cast<int>(a.ks.size()) + 80;
  for (Metric m : AllMetrics()) {
    bool any = false;
    std::ostringstream dat;
    dat.precision(9);
    dat << "# " << MetricName(m) << ": blocks per (K, method) in order; columns: mean delta, mean, std, min, max, runs\n";
    for (int k : a.ks)
      for (const std::string& method : a.methods) {
        dat << "# K=" << k << " method=" << method << "\n";
        bool rows = false;
        for (Tier tier : AllTiers()) {
          const AggregateCell* c = a.Find(k, method, tier);
          if (!c || !c->Get(m) || !c->delta) continue;
          const Spread v = *c->Get(m);
          dat << c->delta->mean << " " << v.mean << " " << v.std << " " << v.min << " " << v.max << " " << v.n << "\n";
          rows = any = true;
        }
        if (!rows) dat << "NaN NaN NaN NaN NaN 0\n";
        dat << "\n\n";
      }
    if (!any) continue;
    const std::string name = MetricName(m);
    ICEF_RETURN_IF_ERROR(WriteFileAtomic(plot_dir / (name + ".dat"), dat.str()));
    const std::string commands = PlotCommands(a, m, name + ".dat");
    std::ostringstream gp;
    // The PDF (vector, for a paper's \includegraphics): the PNG's layout at 150 px per inch (8.1 in wide
    // for three K), its type at 7 pt.
    char pdf_size[48];
    std::snprintf(pdf_size, sizeof pdf_size, "%.2fin,%.2fin", width / 150.0, 480 / 150.0);
    gp << "# gnuplot " << name << ".gp (run in this directory) draws " << name << ".png, " << name
       << ".svg and " << name << ".pdf\n"
       << "set terminal pngcairo noenhanced size " << width << ",480 font \"sans,9\"\nset output \"" << name
       << ".png\"\n"
       << commands << "set terminal svg noenhanced size " << width << ",480 font \"sans,9\"\nset output \""
       << name << ".svg\"\n"
       << commands << "set terminal pdfcairo noenhanced size " << pdf_size
       << " font \"sans,7\"\nset output \"" << name << ".pdf\"\n"
       << commands << "unset output\n";
    ICEF_RETURN_IF_ERROR(WriteFileAtomic(plot_dir / (name + ".gp"), gp.str()));
    if (!have_gnuplot) continue;
    ICEF_RETURN_IF_ERROR(RunGnuplot(plot_dir, name));
    pngs.push_back("plots/" + name + ".png");
  }
  if (!have_gnuplot && note)
    *note = "Plots not drawn: gnuplot is not installed (apt-get install gnuplot-nox); run `gnuplot X.gp` in plots/.";
  return pngs;
}

Status WriteReport(const fs::path& dir, const std::vector<RunRecord>& runs, ReportContext context) {
  const Aggregate aggregate = AggregateRuns(runs);
  if (context.PerIdentity()) {
    const std::vector<RunRecord> pooled = PoolReplicates(runs);
    for (const std::optional<WorstIdentity>& w : WorstIdentities(IdentityRows(pooled))) {
      if (!w) continue;
      const std::string run = w->worst_run->id.Name();
      const auto source = context.run_dirs.find(run);
      ICEF_ASSIGN_OR_RETURN(
          const std::optional<std::string> sheet,
          WriteTrainingViewSheet(dir, run, source == context.run_dirs.end() ? fs::path() : source->second));
      if (sheet) context.run_sheets[run] = *sheet;
    }
  }
  std::string note;
  ICEF_ASSIGN_OR_RETURN(const std::vector<std::string> plots, WritePlots(dir, aggregate, &note));
  if (!note.empty()) context.notes.push_back(note);
  ICEF_RETURN_IF_ERROR(WriteFileAtomic(dir / "report.md", ReportMarkdown(aggregate, runs, context, plots)));
  ICEF_RETURN_IF_ERROR(WriteFileAtomic(dir / "report.tex", ReportLatex(aggregate, context, runs.size())));
  return WriteFileAtomic(dir / "report.json", FormatJson(ReportJson(aggregate, runs, context)));
}

}  // namespace icef::eval
