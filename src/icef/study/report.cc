#include "icef/study/report.h"

#include "icef/io/atomic_file.h"
#include "icef/study/report_internal.h"
#include "icef/study/report_latex.h"
#include "icef/study/training_view_sheet.h"

namespace fs = std::filesystem;

namespace icef::eval {

bool ReportContext::PerIdentity() const { return per_identity || identity_role.rfind("validation", 0) == 0; }

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
