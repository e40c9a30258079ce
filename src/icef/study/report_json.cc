#include <algorithm>
#include <cmath>

#include "icef/study/report.h"
#include "icef/study/report_internal.h"

namespace fs = std::filesystem;

namespace icef::eval {

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
    j["worst_identity"] =
        Json{{"train_fit_face_psnr", worst_json(worst_fit)}, {"observed_psnr", worst_json(worst_psnr)}};
  }
  if (!ctx.identity_role.empty()) j["identity_role"] = ctx.identity_role;
  if (ctx.tier_thresholds) j["tier_thresholds"] = *ctx.tier_thresholds;
  j["verdict"] = Verdict(a);
  Json rj = Json::array();
  for (const RunRecord& r : runs)
    rj.push_back(
        Json{{"name", r.id.Name()},
             {"identity_seed", r.id.identity_seed},
             {"replicate", r.id.replicate},
             {"k", r.id.k},
             {"method", r.id.method},
             {"train_steps", r.train_steps},
             {"train_seconds", r.train_seconds},
             {"eval_seconds", r.eval_seconds},
             {"identity_missing", r.metrics.identity_missing},
             {"train_fit_face_psnr",
              r.metrics.train_fit.face_psnr ? Json(*r.metrics.train_fit.face_psnr) : Json(nullptr)}});
  j["runs"] = std::move(rj);
  return j;
}

Json RunRecordJson(const RunRecord& r) {
  Json j = r.metrics.ToJson();
  j["run"] = Json{{"identity_seed", r.id.identity_seed},
                  {"k", r.id.k},
                  {"method", r.id.method},
                  {"replicate", r.id.replicate},
                  {"train_steps", r.train_steps},
                  {"train_seconds", r.train_seconds},
                  {"eval_seconds", r.eval_seconds}};
  return j;
}

Result<RunRecord> ReadRunRecord(const fs::path& path) {
  ICEF_ASSIGN_OR_RETURN(const Json j, ReadJsonFile(path));
  RunRecord r;
  ICEF_ASSIGN_OR_RETURN(r.metrics, EvalResult::FromJson(j, path.string()));
  const auto run = j.find("run");
  if (run == j.end() || !run->is_object())
    return Status::Error(path.string() + ": run: missing (not a bench run)");
  ICEF_ASSIGN_OR_RETURN(const JsonObjectView v, JsonObjectView::Make(*run, path.string(), "run"));
  ICEF_ASSIGN_OR_RETURN(const double seed, v.Number("identity_seed"));
  if (seed < 0 || seed != std::floor(seed))
    return v.Error("identity_seed", "expected a non-negative integer");
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

}  // namespace icef::eval
