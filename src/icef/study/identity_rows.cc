#include <algorithm>
#include <cstdio>
#include <map>

#include "icef/study/report_internal.h"

namespace icef::eval {

std::string Opt(const std::optional<double>& v, const char* format) {
  if (!v) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, format, *v);
  return buf;
}

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

namespace {

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

}  // namespace

std::string WorstIdentityLine(const std::optional<WorstIdentity>& w, const std::string& what,
                              const std::map<std::string, std::string>& run_sheets) {
  if (!w) return "**Worst identity by " + what + "**: no values.";
  char buf[320];
  std::snprintf(
      buf, sizeof buf,
      "**Worst identity by %s**: seed %llu (mean %.2f dB over its %d run%s; lowest run `%s`, %.2f dB).",
      what.c_str(), static_cast<unsigned long long>(w->seed), w->mean, w->runs, w->runs == 1 ? "" : "s",
      w->worst_run->id.Name().c_str(), w->worst_value);
  std::string line = buf;
  const auto sheet = run_sheets.find(w->worst_run->id.Name());
  if (sheet != run_sheets.end())
    line +=
        " Its training views, truth left and render right: [" + sheet->second + "](" + sheet->second + ")";
  return line;
}

// The worst identities of a per-identity report: by training-view face PSNR, then by observed PSNR.
std::array<std::optional<WorstIdentity>, 2> WorstIdentities(const std::vector<IdentityRow>& rows) {
  return {FindWorstIdentity(rows, &IdentityRow::train_face_psnr),
          FindWorstIdentity(rows, &IdentityRow::observed_psnr)};
}

}  // namespace icef::eval
