#include "icef/app/sheet_app.h"

#include "icef/data/dataset.h"
#include "icef/io/image.h"

namespace icef {

Status RunSheet(const SheetAppOptions& options, std::ostream& out) {
  std::vector<Dataset> datasets;
  for (const std::string& d : options.datasets) {
    ICEF_ASSIGN_OR_RETURN(Dataset dataset, LoadDataset(d));
    datasets.push_back(std::move(dataset));
  }
  ICEF_ASSIGN_OR_RETURN(const Image sheet, datasets.size() == 1
                                               ? synth::MakeContactSheet(datasets[0], options.sheet)
                                               : synth::MakeTrainingSheet(datasets, options.sheet));
  ICEF_RETURN_IF_ERROR(WritePng(options.out, sheet));
  out << "wrote " << options.out.string() << " (" << sheet.width << "x" << sheet.height << ")\n";
  return Status::Ok();
}

}  // namespace icef
