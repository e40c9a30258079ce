#include "icef/app/import_app.h"

#include <optional>

#include "icef/data/dataset_import.h"

namespace icef {

Status RunImport(const ImportAppOptions& options, std::ostream& out_stream) {
  const std::optional<DatasetFormat> format = ParseDatasetFormat(options.format);
  if (!format)
    return Status::Error("--format: expected auto, nerface, instant-ngp or icef, got '" + options.format +
                         "'");
  ImportOptions import;
  import.format = *format;
  import.link_images = options.link;
  ICEF_ASSIGN_OR_RETURN(const ImportReport report, ImportDataset(options.src, options.out, import));
  out_stream << report.ToString() << "\n";
  return Status::Ok();
}

}  // namespace icef
