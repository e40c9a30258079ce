// The bench report as LaTeX tables (report.tex, beside report.md): for a paper, the numbers of the
// aggregate (study/report.h) in booktabs tables, one per K (rows: tier x method; columns: PSNR, SSIM,
// LPIPS where measured, expr_gain, id_distance_gt, id_excess) and one of the far tier across K.
// Cells are the mean +- sample std over identities; the best mean of each tier is set in bold
// among the methods that reproduce at least kMinExpressionGain of the expression (a face that does
// not move is never best; expr_gain itself: the closest to 1). Needs \usepackage{booktabs}.
#pragma once

#include <string>

#include "icef/study/report.h"

namespace icef::eval {

// The whole file: a comment header (source, identities, what a cell is) and the tables.
std::string ReportLatex(const Aggregate& aggregate, const ReportContext& context, size_t num_runs);

// Text escaped for LaTeX's text mode (\ { } $ & # ^ _ % ~); a `code` span (Markdown's backticks)
// becomes \texttt{code}, closed at the end if the text leaves it open.
std::string LatexEscape(const std::string& text);

}  // namespace icef::eval
