#include "icef/data/dataset_import.h"

#include <unistd.h>

#include <cstdio>
#include <sstream>

#include "icef/core/enum_table.h"
#include "icef/io/json_util.h"

namespace icef {

namespace fs = std::filesystem;

namespace {

constexpr std::array<EnumEntry<DatasetFormat>, 4> kFormatNames = {
    {{DatasetFormat::kAuto, "auto"},
     {DatasetFormat::kIcef, "icef"},
     {DatasetFormat::kNerface, "nerface"},
     {DatasetFormat::kInstantNgp, "instant-ngp"}}};

}  // namespace

const char* DatasetFormatName(DatasetFormat format) { return EnumName(kFormatNames, format); }

std::optional<DatasetFormat> ParseDatasetFormat(const std::string& name) {
  return ParseEnum(kFormatNames, name);
}

Result<DatasetFormat> DetectDatasetFormat(const fs::path& dir) {
  const fs::path file = dir / "transforms_train.json";
  ICEF_ASSIGN_OR_RETURN(const Json doc, ReadJsonFile(file));
  if (!doc.is_object()) return Status::Error(file.string() + ": expected an object");
  if (doc.contains("expression_dim")) return DatasetFormat::kIcef;
  bool nerface = doc.contains("intrinsics");
  std::error_code ec;
  nerface = nerface || fs::is_directory(dir / "bg", ec);
  if (const auto it = doc.find("frames"); it != doc.end() && it->is_array())
    for (const Json& frame : *it)
      nerface = nerface || (frame.is_object() && (frame.contains("intrinsics") || frame.contains("bbox")));
  return nerface ? DatasetFormat::kNerface : DatasetFormat::kInstantNgp;
}

Status ImportOptions::Validate() const { return Status::Ok(); }

std::string ImportOptions::ToString() const {
  return std::string("ImportOptions(format=") + DatasetFormatName(format) +
         ", link_images=" + (link_images ? "true" : "false") + ")";
}

std::string ImportReport::ToString() const {
  std::ostringstream os;
  os << "imported a " << DatasetFormatName(format) << " dataset into " << dataset.root.string() << ": train "
     << dataset.train.size() << ", test " << dataset.test.size() << ", val " << dataset.val.size()
     << " frames, " << images << " images "
     << "(expression_dim " << dataset.expression_dim << ")";
  return os.str();
}

namespace {

Status CopyOrLink(const fs::path& from, const fs::path& to, bool link) {
  std::error_code ec;
  if (link) {
    fs::create_hard_link(from, to, ec);
    if (!ec) return Status::Ok();
    ec.clear();  // e.g. across filesystems: fall back to a copy
  }
  fs::copy_file(from, to, fs::copy_options::none, ec);
  if (ec) return Status::Error(to.string() + ": cannot copy " + from.string() + ": " + ec.message());
  return Status::Ok();
}

std::string NewName(const char* split, size_t index, const char* suffix, const fs::path& original) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "images/%s_%04zu%s", split, index, suffix);
  std::string ext = original.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return buffer + ext;
}

// Copies every frame's images into `out` and writes the transforms files there.
Result<int> WriteConverted(const Dataset& source, Dataset& converted, const fs::path& out, bool link) {
  int images = 0;
  fs::create_directories(out / "images");
  const std::pair<const char*, std::vector<Frame>*> splits[] = {
      {"train", &converted.train}, {"test", &converted.test}, {"val", &converted.val}};
  for (const auto& [split, frames] : splits) {
    for (size_t i = 0; i < frames->size(); ++i) {
      Frame& f = (*frames)[i];
      const fs::path from = source.root / f.file_path;
      f.file_path = NewName(split, i, "", from);
      ICEF_RETURN_IF_ERROR(CopyOrLink(from, out / f.file_path, link));
      ++images;
      if (f.neutral_file_path) {
        const fs::path neutral_from = source.root / *f.neutral_file_path;
        f.neutral_file_path = NewName(split, i, "_neutral", neutral_from);
        ICEF_RETURN_IF_ERROR(CopyOrLink(neutral_from, out / *f.neutral_file_path, link));
        ++images;
      }
    }
  }
  if (source.background_file_path) {
    const fs::path from = source.root / *source.background_file_path;
    std::string ext = from.extension().string();
    converted.background_file_path = "background" + ext;
    ICEF_RETURN_IF_ERROR(CopyOrLink(from, out / *converted.background_file_path, link));
    ++images;
  }
  converted.root = out;
  ICEF_RETURN_IF_ERROR(SaveDataset(converted));
  return images;
}

}  // namespace

Result<ImportReport> ImportDataset(const fs::path& src, const fs::path& dst, const ImportOptions& options) {
  ICEF_RETURN_IF_ERROR(options.Validate());
  std::error_code ec;
  if (fs::exists(dst, ec) && !(fs::is_directory(dst, ec) && fs::is_empty(dst, ec)))
    return Status::Error(dst.string() +
                         ": already exists and is not an empty directory (choose a new --out)");
  if (fs::exists(dst, ec) && fs::equivalent(src, dst, ec))
    return Status::Error(dst.string() + ": the destination must differ from the source");

  ImportReport report;
  if (options.format == DatasetFormat::kAuto) {
    ICEF_ASSIGN_OR_RETURN(report.format, DetectDatasetFormat(src));
  } else {
    report.format = options.format;
  }
  ICEF_ASSIGN_OR_RETURN(const Dataset source, LoadDataset(src));
  const std::string train_file = (src / "transforms_train.json").string();
  if (report.format == DatasetFormat::kNerface && source.expression_dim == 0)
    return Status::Error(train_file +
                         ": frames[0].expression: missing (NerFace datasets have per-frame expressions)");

  const fs::path parent = dst.has_parent_path() ? dst.parent_path() : fs::path(".");
  if (!fs::is_directory(parent, ec)) return Status::Error(dst.string() + ": parent directory does not exist");
  const fs::path temp = parent / std::string(1, '.')
                                     .append(dst.filename().string())
                                     .append(".import-")
                                     .append(std::to_string(::getpid()));
  fs::remove_all(temp, ec);
  fs::create_directories(temp, ec);
  if (ec) return Status::Error(temp.string() + ": cannot create directory: " + ec.message());

  Dataset converted = source;
  Result<int> written = WriteConverted(source, converted, temp, options.link_images);
  Result<Dataset> verified = written.ok() ? LoadDataset(temp) : Result<Dataset>(written.status());
  if (!verified.ok()) {
    fs::remove_all(temp, ec);
    return verified.status().WithContext("import into " + dst.string());
  }
  if (fs::exists(dst, ec)) fs::remove(dst, ec);  // an empty directory, checked above
  fs::rename(temp, dst, ec);
  if (ec) {
    const std::string message = ec.message();
    fs::remove_all(temp, ec);
    return Status::Error(dst.string() + ": cannot move the imported dataset into place: " + message);
  }
  report.images = *written;
  report.dataset = std::move(*verified);
  report.dataset.root = dst;
  return report;
}

}  // namespace icef
