#include "icef/app/info_app.h"

#include "icef/core/parallel.h"
#include "icef/data/dataset.h"
#include "icef/data/dataset_summary.h"
#include "icef/io/json_util.h"

namespace icef {

Status RunInfo(const InfoAppOptions& options, std::ostream& out) {
  ICEF_ASSIGN_OR_RETURN(const Dataset dataset, LoadDataset(options.dataset));
  if (dataset.train.empty())
    return Status::Error(
        (dataset.root / "transforms_train.json").string() +
        ": frames: the train split has no frames (a dataset needs at least one training frame)");
  const DatasetSummary summary = SummarizeDataset(dataset, Executor());
  out << (options.json ? FormatJson(summary.ToJson()) : summary.ToString());
  return Status::Ok();
}

}  // namespace icef
