#include "icef/study/report_latex.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

namespace icef::eval {

namespace {

struct Column {
  Metric metric;
  const char* header;
  bool bold;  // whether a best value is marked (id_excess has no "better" direction)
};

// The per-K tables' columns, those without any value in the aggregate left out.
std::vector<Column> Columns(const Aggregate& a) {
  static const Column kAll[] = {
      {Metric::kPsnr, "PSNR (dB) $\\uparrow$", true},
      {Metric::kSsim, "SSIM $\\uparrow$", true},
      {Metric::kLpips, "LPIPS $\\downarrow$", true},
      {Metric::kExprGain, "Expr.\\ gain", true},
      {Metric::kIdDistanceGt, "ID dist.\\ to GT $\\downarrow$", true},
      {Metric::kIdExcess, "ID excess", false},
  };
  std::vector<Column> out;
  for (const Column& c : kAll) {
    bool any = false;
    for (const AggregateCell& cell : a.cells) any = any || cell.Get(c.metric).has_value();
    if (any) out.push_back(c);
  }
  return out;
}

std::string Number(double v, Metric m, bool spread = false) {
  std::string format = MetricFormat(m);
  if (spread && format.size() > 1 && format[1] == '+') format.erase(1, 1);  // a std has no sign to show
  char buf[32];
  std::snprintf(buf, sizeof buf, format.c_str(), v);
  return buf;
}

// Whether a cell may be marked best: it reproduces at least kMinExpressionGain of the expression
// (or the tier has no measured expression).
bool Moves(const AggregateCell& cell) {
  const std::optional<Spread> gain = cell.Get(Metric::kExprGain);
  return !gain || gain->mean >= kMinExpressionGain;
}

// Of the cells (one per method), the printed mean that is best on the metric among those that
// move; empty when fewer than two cells have a value (nothing to compare) or none moves.
std::string BestMean(const std::vector<const AggregateCell*>& cells, Metric m) {
  std::optional<double> best;
  int present = 0;
  for (const AggregateCell* cell : cells) {
    const std::optional<Spread> s = cell ? cell->Get(m) : std::nullopt;
    if (!s) continue;
    ++present;
    if (!Moves(*cell)) continue;
    const double v = s->mean;
    if (!best) {
      best = v;
    } else if (m == Metric::kExprGain) {
      if (std::abs(v - 1.0) < std::abs(*best - 1.0)) best = v;
    } else if (HigherIsBetter(m) ? v > *best : v < *best) {
      best = v;
    }
  }
  return present >= 2 && best ? Number(*best, m) : std::string();
}

std::string Cell(const AggregateCell* cell, Metric m, const std::string& best) {
  const std::optional<Spread> s = cell ? cell->Get(m) : std::nullopt;
  if (!s) return "--";
  const std::string mean = Number(s->mean, m);
  const bool bold = !best.empty() && mean == best && Moves(*cell);
  std::string out = "$" + (bold ? "\\mathbf{" + mean + "}" : mean);
  if (s->n > 1) out += " \\pm " + Number(s->std, m, /*spread=*/true);
  return out + "$";
}

// The (K, method, tier) cell, or null when no run has frames in the tier.
const AggregateCell* Find(const Aggregate& a, int k, const std::string& method, Tier tier) {
  const AggregateCell* cell = a.Find(k, method, tier);
  return cell && cell->runs > 0 ? cell : nullptr;
}

std::string Identities(const Aggregate& a) {
  std::string out;
  for (size_t i = 0; i < a.identities.size(); ++i) out += (i ? ", " : "") + std::to_string(a.identities[i]);
  return out;
}

// What every caption says about the cells.
std::string CaptionTail(const Aggregate& a, const ReportContext& ctx) {
  std::ostringstream s;
  s << "Mean $\\pm$ sample std over " << a.identities.size() << " identit"
    << (a.identities.size() == 1 ? "y" : "ies") << " (seeds " << Identities(a);
  if (!ctx.identity_role.empty()) s << "; " << LatexEscape(ctx.identity_role);
  s << "). Bold: the best mean of a tier among the methods that reproduce at least "
    << static_cast<int>(std::lround(100 * kMinExpressionGain))
    << "\\% of the expression (expr.\\ gain: the closest to 1, the full expression).";
  return s.str();
}

void PerKTable(std::ostringstream& s, const Aggregate& a, const ReportContext& ctx, int k,
               const std::vector<Column>& columns) {
  s << "\\begin{table}[t]\n\\centering\n\\small\n";
  s << "\\caption{" << LatexEscape(ctx.title) << ", $K = " << k << "$ training frames. "
    << CaptionTail(a, ctx)
    << " Expr.\\ gain: share of the true expression change the render reproduces in the brow, eye and mouth "
    << "region; ID excess: identity drift beyond the expression's own (negative: under-expression).}\n";
  s << "\\label{tab:icef-bench-k" << k << "}\n";
  s << "\\begin{tabular}{ll" << std::string(columns.size(), 'c') << "}\n\\toprule\n";
  s << "Tier & Method";
  for (const Column& c : columns) s << " & " << c.header;
  s << " \\\\\n";
  bool first_tier = true;
  for (Tier tier : AllTiers()) {
    std::vector<const AggregateCell*> cells;
    bool any = false;
    for (const std::string& method : a.methods) {
      cells.push_back(Find(a, k, method, tier));
      any = any || cells.back() != nullptr;
    }
    if (!any) continue;
    s << (first_tier ? "\\midrule\n" : "\\addlinespace\n");
    first_tier = false;
    std::vector<std::string> best;
    for (const Column& c : columns) best.push_back(c.bold ? BestMean(cells, c.metric) : std::string());
    bool first_row = true;
    for (size_t i = 0; i < a.methods.size(); ++i) {
      if (!cells[i]) continue;
      s << (first_row ? TierName(tier) : "") << " & \\texttt{" << LatexEscape(a.methods[i]) << "}";
      for (size_t j = 0; j < columns.size(); ++j) s << " & " << Cell(cells[i], columns[j].metric, best[j]);
      s << " \\\\\n";
      first_row = false;
    }
  }
  s << "\\bottomrule\n\\end{tabular}\n\\end{table}\n\n";
}

void FarTable(std::ostringstream& s, const Aggregate& a, const ReportContext& ctx) {
  static const Metric kMetrics[] = {Metric::kPsnr, Metric::kExprGain, Metric::kIdDistanceGt};
  static const char* kHeaders[] = {"PSNR", "Expr.", "ID"};
  s << "\\begin{table}[t]\n\\centering\n\\small\n";
  s << "\\caption{" << LatexEscape(ctx.title) << ", far tier (expressions far from every training "
    << "expression) against the number of training frames $K$: PSNR (dB, higher is better), expression "
    << "gain (1 = the full expression) and identity distance to the ground truth (lower is better). "
    << CaptionTail(a, ctx) << "}\n";
  s << "\\label{tab:icef-bench-far}\n";
  s << "\\begin{tabular}{l";
  for (size_t i = 0; i < a.ks.size(); ++i) s << "ccc";
  s << "}\n\\toprule\n";
  for (int k : a.ks) s << " & \\multicolumn{3}{c}{$K = " << k << "$}";
  s << " \\\\\n";
  for (size_t i = 0; i < a.ks.size(); ++i) s << "\\cmidrule(lr){" << 2 + 3 * i << "-" << 4 + 3 * i << "}";
  s << "\nMethod";
  for (size_t i = 0; i < a.ks.size(); ++i)
    for (const char* h : kHeaders) s << " & " << h;
  s << " \\\\\n\\midrule\n";
  std::vector<std::vector<std::string>> best;  // [K][metric]
  for (int k : a.ks) {
    std::vector<const AggregateCell*> cells;
    for (const std::string& method : a.methods) cells.push_back(Find(a, k, method, Tier::kFar));
    best.emplace_back();
    for (Metric m : kMetrics) best.back().push_back(BestMean(cells, m));
  }
  for (const std::string& method : a.methods) {
    s << "\\texttt{" << LatexEscape(method) << "}";
    for (size_t i = 0; i < a.ks.size(); ++i) {
      const AggregateCell* cell = Find(a, a.ks[i], method, Tier::kFar);
      for (size_t j = 0; j < 3; ++j) s << " & " << Cell(cell, kMetrics[j], best[i][j]);
    }
    s << " \\\\\n";
  }
  s << "\\bottomrule\n\\end{tabular}\n\\end{table}\n";
}

}  // namespace

std::string LatexEscape(const std::string& text) {
  std::string out;
  bool code = false;  // inside `...`: set in typewriter type, as Markdown does
  for (char c : text) {
    switch (c) {
      case '`':
        out += code ? "}" : "\\texttt{";
        code = !code;
        break;
      case '\\':
        out += "\\textbackslash{}";
        break;
      case '{':
      case '}':
      case '$':
      case '&':
      case '#':
      case '_':
      case '%':
        out += '\\';
        out += c;
        break;
      case '^':
        out += "\\textasciicircum{}";
        break;
      case '~':
        out += "\\textasciitilde{}";
        break;
      default:
        out += c;
    }
  }
  if (code) out += "}";
  return out;
}

std::string ReportLatex(const Aggregate& a, const ReportContext& ctx, size_t num_runs) {
  std::ostringstream s;
  s << "% " << ctx.title << ": generated by `icef bench` from " << num_runs
    << " runs (report.md and report.json hold the same numbers).\n"
    << "% Needs \\usepackage{booktabs}. Cells: mean \\pm sample std over identities " << Identities(a)
    << ".\n\n";
  if (a.cells.empty()) {
    s << "% No runs with metrics.\n";
    return s.str();
  }
  const std::vector<Column> columns = Columns(a);
  for (int k : a.ks) PerKTable(s, a, ctx, k, columns);
  FarTable(s, a, ctx);
  return s.str();
}

}  // namespace icef::eval
