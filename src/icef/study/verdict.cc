#include <algorithm>
#include <cstdio>
#include <optional>

#include "icef/core/enum_table.h"
#include "icef/study/aggregate.h"
#include "icef/study/report_internal.h"

namespace icef::eval {

constexpr std::array<EnumEntry<Outcome>, 5> kOutcomeNames = {
    {{Outcome::kBetter, "better"},
     {Outcome::kUnderExpresses, "under-expresses"},
     {Outcome::kWorseIdentity, "not better on identity"},
     {Outcome::kWorsePsnr, "not better on PSNR"},
     {Outcome::kNoData, "no data"}}};

const char* OutcomeName(Outcome o) { return EnumName(kOutcomeNames, o); }

Json PairVerdict::ToJson() const {
  return Json{{"k", k},
              {"tier", TierName(tier)},
              {"method", method},
              {"other", other},
              {"outcome", OutcomeName(outcome)}};
}

PairVerdict ComparePair(const Aggregate& a, int k, Tier tier, const std::string& method,
                        const std::string& other) {
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

namespace {

bool Has(const std::vector<std::string>& list, const std::string& name) {
  return std::find(list.begin(), list.end(), name) != list.end();
}

std::string CellValue(const Aggregate& a, int k, const std::string& method, Tier tier, Metric m) {
  const AggregateCell* c = a.Find(k, method, tier);
  return c ? Pm(c->Get(m), MetricFormat(m)) : std::string("-");
}

// "K=3 vs warp: better (psnr 24.1 vs 23.2)": the outcome and the metric that decided it.
std::string PairDetail(const Aggregate& a, const PairVerdict& v) {
  std::string d = "K=" + std::to_string(v.k) + " vs " + v.other + ": " + OutcomeName(v.outcome);
  Metric shown = Metric::kExprGain;
  if (v.outcome == Outcome::kWorseIdentity) shown = Metric::kIdDistanceGt;
  if (v.outcome == Outcome::kWorsePsnr || v.outcome == Outcome::kBetter) shown = Metric::kPsnr;
  if (v.outcome != Outcome::kNoData)
    d += std::string(" (") + MetricName(shown) + " " + CellValue(a, v.k, v.method, v.tier, shown) + " vs " +
         CellValue(a, v.k, v.other, v.tier, shown) + ")";
  return d;
}

// One tier's line: `primary` against `others` (named `label`) over every K; nullopt without pairs.
std::optional<std::string> TierLine(const Aggregate& a, const std::string& primary, Tier tier,
                                    const std::vector<std::string>& others, const std::string& label) {
  int pairs = 0, better = 0;
  std::string detail;
  for (const PairVerdict& v : a.verdicts) {
    if (v.method != primary || v.tier != tier || v.outcome == Outcome::kNoData || !Has(others, v.other))
      continue;
    ++pairs;
    better += v.outcome == Outcome::kBetter;
    detail += (detail.empty() ? "" : "; ") + PairDetail(a, v);
  }
  if (pairs == 0) return std::nullopt;
  std::string head;
  if (better == pairs)
    head = primary + " is **better** in every comparison";
  else if (better == 0)
    head = primary + " is **not better** in any comparison";
  else
    head = primary + " is better in **" + std::to_string(better) + " of " + std::to_string(pairs) +
           "** comparisons";
  return "**" + std::string(TierName(tier)) + " tier, " + primary + " vs " + label + "**: " + head + ". " +
         detail + ".";
}

// How much of the expression each method shows at K, and its identity drift against the truth's own.
void ExpressionLines(const Aggregate& a, int k, std::vector<std::string>* lines) {
  std::string gains, drift, under;
  for (const std::string& method : a.methods) {
    std::string g;
    for (Tier tier : {Tier::kNear, Tier::kModerate, Tier::kFar}) {
      const AggregateCell* c = a.Find(k, method, tier);
      char buf[32] = "-";
      if (c && c->Get(Metric::kExprGain))
        std::snprintf(buf, sizeof buf, "%.2f", c->Get(Metric::kExprGain)->mean);
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
      std::snprintf(buf, sizeof buf, "`%s` (%.0f%%)", method.c_str(),
                    100 * far->Get(Metric::kExprGain)->mean);
      under += (under.empty() ? "" : ", ") + std::string(buf);
    }
  }
  lines->push_back(
      "**Expression reproduced, K=" + std::to_string(k) +
      "** (expr_gain near/moderate/far, mean over identities; 1 = the full expression, 0 = none): " + gains +
      "." +
      (under.empty()
           ? std::string()
           : " **Under-expression** in the far tier (less than half of the expression): " + under + "."));
  if (!drift.empty())
    lines->push_back(
        "**Identity drift beyond the ground truth's own, K=" + std::to_string(k) +
        "** (far-tier id_excess = id_distance - id_distance_reference; negative = the render moves "
        "less than the truth): " +
        drift + ".");
}

}  // namespace

std::vector<std::string> Verdict(const Aggregate& a) {
  std::vector<std::string> lines;
  std::vector<std::string> baselines;
  for (const std::string& b : Baselines())
    if (Has(a.methods, b)) baselines.push_back(b);
  const bool has_icef = Has(a.methods, "icef");
  if (!has_icef || baselines.empty())
    lines.push_back("No verdict: the bench did not run icef together with a baseline (warp, nerface).");
  auto add = [&](const std::string& primary, Tier tier, const std::vector<std::string>& others,
                 const std::string& label) {
    if (std::optional<std::string> line = TierLine(a, primary, tier, others, label)) lines.push_back(*line);
  };
  if (has_icef && !baselines.empty()) {
    std::vector<std::string> ablations;
    for (const std::string& m : a.methods)
      if (m != "icef" && !Has(baselines, m)) ablations.push_back(m);
    for (Tier tier : {Tier::kFar, Tier::kModerate, Tier::kNear})
      add("icef", tier, baselines, "the baselines");
    add("icef", Tier::kFar, ablations, "its ablations and the other methods");
  }
  if (Has(a.methods, "icef-prior")) {
    std::vector<std::string> others;
    for (const std::string& m : a.methods)
      if (m != "icef-prior") others.push_back(m);
    for (Tier tier : {Tier::kFar, Tier::kModerate, Tier::kNear})
      add("icef-prior", tier, others, "every other method");
  }
  for (int k : a.ks) ExpressionLines(a, k, &lines);
  return lines;
}

}  // namespace icef::eval
