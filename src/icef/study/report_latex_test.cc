#include "icef/study/report_latex.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace icef::eval {
namespace {

namespace fs = std::filesystem;

// A run with one observed frame (PSNR far_psnr + 10) and one far frame.
RunRecord MakeRun(uint64_t seed, int k, const std::string& method, double far_psnr, double far_gain,
                  double far_id_gt) {
  RunRecord r;
  r.id = RunId{seed, k, method};
  r.metrics.method = method;
  r.metrics.identity_available = true;
  FrameMetrics obs;
  obs.file_path = "o.png";
  obs.tier = Tier::kObserved;
  obs.psnr = far_psnr + 10;
  obs.ssim = 0.9;
  FrameMetrics far;
  far.file_path = "f.png";
  far.tier = Tier::kFar;
  far.delta = 1.5;
  far.psnr = far_psnr;
  far.ssim = 0.8;
  far.expr_gain = far_gain;
  far.expr_true_rms = 0.05;
  far.id_distance = 0.2;
  far.id_distance_gt = far_id_gt;
  far.id_distance_reference = 0.25;
  far.id_excess = -0.05;
  r.metrics.frames = {obs, far};
  r.metrics.tiers = AggregateTiers(r.metrics.frames);
  return r;
}

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

// The method's rows in the table with the label, in order (per K tables: one per tier).
std::vector<std::string> Rows(const std::string& tex, const std::string& label, const std::string& method) {
  std::istringstream in(tex);
  std::vector<std::string> rows;
  bool in_table = false;
  for (std::string line; std::getline(in, line);) {
    if (line.find("\\label{" + label + "}") != std::string::npos) in_table = true;
    if (in_table && line.find("\\texttt{" + method + "}") != std::string::npos) rows.push_back(line);
    if (line == "\\end{table}") in_table = false;
  }
  return rows;
}
std::string Row(const std::string& tex, const std::string& label, const std::string& method) {
  const std::vector<std::string> rows = Rows(tex, label, method);
  return rows.empty() ? "" : rows.front();
}

// Every row of every tabular has as many cells as its column spec (LaTeX stops on one more).
void ExpectRowsMatchColumns(const std::string& tex) {
  std::istringstream in(tex);
  int columns = -1, rows = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("\\begin{tabular}{", 0) == 0) {
      columns = static_cast<int>(line.size() - std::string("\\begin{tabular}{}").size());
      continue;
    }
    if (line.rfind("\\end{tabular}", 0) == 0) columns = -1;
    if (columns < 0 || line.size() < 2 || line.compare(line.size() - 2, 2, "\\\\") != 0) continue;
    int cells = 1;
    for (size_t i = 0; i < line.size(); ++i)
      if (line[i] == '&' && (i == 0 || line[i - 1] != '\\')) ++cells;
    for (size_t at = line.find("\\multicolumn{"); at != std::string::npos;
         at = line.find("\\multicolumn{", at + 1))
      cells += std::stoi(line.substr(at + 13)) - 1;
    EXPECT_EQ(cells, columns) << line;
    ++rows;
  }
  EXPECT_GT(rows, 0);
}

TEST(ReportLatexTest, TablesPerKAndFarTierWithMeanAndSpread) {
  // K = 5: "icef-prior" PSNR 29 / 31 over two identities (mean 30, sample std sqrt 2); "warp" 25 / 25.
  const std::vector<RunRecord> runs = {
      MakeRun(1, 5, "icef-prior", 29, 0.8, 0.10), MakeRun(2, 5, "icef-prior", 31, 0.9, 0.12),
      MakeRun(1, 5, "warp", 25, 0.5, 0.30),       MakeRun(2, 5, "warp", 25, 0.5, 0.30),
      MakeRun(1, 3, "icef-prior", 27, 0.7, 0.15), MakeRun(2, 3, "icef-prior", 27, 0.7, 0.15)};
  ReportContext ctx;
  ctx.identity_role = "test: never used for tuning";
  const std::string tex = ReportLatex(AggregateRuns(runs), ctx, runs.size());

  // One table per K and the far tier's across K, each a complete booktabs tabular.
  EXPECT_EQ(Count(tex, "\\begin{table}"), 3);
  EXPECT_EQ(Count(tex, "\\end{table}"), 3);
  EXPECT_EQ(Count(tex, "\\toprule"), 3);
  EXPECT_EQ(Count(tex, "\\bottomrule"), 3);
  EXPECT_NE(tex.find("\\label{tab:icef-bench-k3}"), std::string::npos);
  EXPECT_NE(tex.find("\\label{tab:icef-bench-k5}"), std::string::npos);
  EXPECT_NE(tex.find("\\label{tab:icef-bench-far}"), std::string::npos);
  EXPECT_EQ(std::count(tex.begin(), tex.end(), '{'), std::count(tex.begin(), tex.end(), '}'));
  ExpectRowsMatchColumns(tex);
  EXPECT_NE(tex.find("seeds 1, 2; test: never used for tuning"), std::string::npos);
  // No LPIPS was measured: no LPIPS column.
  EXPECT_EQ(tex.find("LPIPS"), std::string::npos);

  // K = 5, far tier: 30.00 +- 1.41 dB, the best PSNR (bold); warp's 25.00 has no spread to show but
  // two identities, so "\pm 0.00".
  const std::vector<std::string> prior = Rows(tex, "tab:icef-bench-k5", "icef-prior");
  ASSERT_EQ(prior.size(), 2u);  // observed, far (the tiers without frames left out)
  EXPECT_NE(prior[0].find("$\\mathbf{40.00} \\pm 1.41$"), std::string::npos) << prior[0];
  const std::string prior_far = prior[1];
  EXPECT_NE(prior_far.find("$\\mathbf{30.00} \\pm 1.41$"), std::string::npos) << prior_far;
  const std::string far_table = Row(tex, "tab:icef-bench-far", "icef-prior");
  EXPECT_NE(far_table.find("$27.00 \\pm 0.00$"), std::string::npos) << far_table;             // K = 3, alone
  EXPECT_NE(far_table.find("$\\mathbf{30.00} \\pm 1.41$"), std::string::npos) << far_table;   // K = 5 PSNR
  EXPECT_NE(far_table.find("$\\mathbf{0.850} \\pm 0.071$"), std::string::npos) << far_table;  // expr_gain
  EXPECT_NE(far_table.find("$\\mathbf{0.110} \\pm 0.014$"), std::string::npos)
      << far_table;  // id_distance_gt
  // id_excess is signed (-0.050), its spread is not.
  EXPECT_NE(prior_far.find("$-0.050 \\pm 0.000$"), std::string::npos) << prior_far;
  const std::string warp_far = Row(tex, "tab:icef-bench-far", "warp");
  EXPECT_NE(warp_far.find("$25.00 \\pm 0.00$"), std::string::npos) << warp_far;
  EXPECT_EQ(warp_far.find("mathbf"), std::string::npos) << warp_far;
  EXPECT_NE(warp_far.find("--"), std::string::npos) << warp_far;  // no K = 3 run
}

TEST(ReportLatexTest, AFaceThatDoesNotMoveIsNeverBest) {
  // "static" has the higher PSNR and identity but reproduces none of the expression.
  const std::vector<RunRecord> runs = {MakeRun(1, 5, "icef-prior", 28, 0.8, 0.2),
                                       MakeRun(1, 5, "static", 35, 0.0, 0.05)};
  const std::string tex = ReportLatex(AggregateRuns(runs), ReportContext{}, runs.size());
  const std::string moving = Row(tex, "tab:icef-bench-far", "icef-prior");
  const std::string still = Row(tex, "tab:icef-bench-far", "static");
  EXPECT_NE(moving.find("$\\mathbf{28.00}$"), std::string::npos) << moving;  // one identity: no spread
  EXPECT_NE(still.find("$35.00$"), std::string::npos) << still;
  EXPECT_EQ(still.find("mathbf"), std::string::npos) << still;
}

TEST(ReportLatexTest, ExpressionGainClosestToOneIsBest) {
  // 1.3 over-expresses by more than 0.8 under-expresses.
  const std::vector<RunRecord> runs = {MakeRun(1, 5, "a", 28, 0.8, 0.2), MakeRun(1, 5, "b", 28, 1.3, 0.2)};
  const std::string tex = ReportLatex(AggregateRuns(runs), ReportContext{}, runs.size());
  EXPECT_NE(Row(tex, "tab:icef-bench-far", "a").find("$\\mathbf{0.800}$"), std::string::npos);
  EXPECT_NE(Row(tex, "tab:icef-bench-far", "b").find("$1.300$"), std::string::npos);
  // Equal printed means are both best.
  EXPECT_NE(Row(tex, "tab:icef-bench-far", "b").find("$\\mathbf{28.00}$"), std::string::npos);
  EXPECT_NE(Row(tex, "tab:icef-bench-far", "a").find("$\\mathbf{28.00}$"), std::string::npos);
}

TEST(ReportLatexTest, EscapesTextAndHandlesNoRuns) {
  EXPECT_EQ(LatexEscape("a_b & 50% #1 {x} $y$ ~z^2 \\"),
            "a\\_b \\& 50\\% \\#1 \\{x\\} \\$y\\$ \\textasciitilde{}z\\textasciicircum{}2 \\textbackslash{}");
  EXPECT_EQ(LatexEscape("seeds 101 and up (`icef bench --validation`)"),
            "seeds 101 and up (\\texttt{icef bench --validation})");
  EXPECT_EQ(LatexEscape("open `code_x"), "open \\texttt{code\\_x}");
  const std::vector<RunRecord> runs = {MakeRun(1, 5, "my_method", 28, 0.8, 0.2)};
  const std::string tex = ReportLatex(AggregateRuns(runs), ReportContext{}, runs.size());
  EXPECT_NE(tex.find("\\texttt{my\\_method}"), std::string::npos);
  EXPECT_EQ(tex.find("my_method"), std::string::npos);
  const std::string empty = ReportLatex(AggregateRuns({}), ReportContext{}, 0);
  EXPECT_EQ(empty.find("\\begin{table}"), std::string::npos);
}

TEST(ReportLatexTest, WriteReportWritesTheTexBesideTheMarkdown) {
  const fs::path dir = fs::temp_directory_path() / ("icef_report_latex_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::vector<RunRecord> runs = {MakeRun(1, 5, "icef-prior", 28, 0.8, 0.2)};
  ASSERT_TRUE(WriteReport(dir, runs, ReportContext{}).ok());
  std::ifstream in(dir / "report.tex");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), ReportLatex(AggregateRuns(runs), ReportContext{}, runs.size()));
  EXPECT_TRUE(fs::exists(dir / "report.md"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace icef::eval
