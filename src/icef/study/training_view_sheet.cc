#include "icef/study/training_view_sheet.h"

#include <algorithm>
#include <system_error>
#include <vector>

#include "icef/io/image.h"

namespace icef::eval {

namespace fs = std::filesystem;

namespace {

constexpr char kPairSuffix[] = "_vs_truth.png";

// The run's training-view pairs, sorted by name (= frame order).
std::vector<fs::path> TrainingViewPairs(const fs::path& renders) {
  std::vector<fs::path> pairs;
  std::error_code ec;
  if (!fs::is_directory(renders, ec)) return pairs;
  for (const fs::directory_entry& e : fs::directory_iterator(renders, ec)) {
    const std::string name = e.path().filename().string();
    const size_t n = sizeof kPairSuffix - 1;
    if (name.rfind("fit_", 0) == 0 && name.size() > n && name.compare(name.size() - n, n, kPairSuffix) == 0)
      pairs.push_back(e.path());
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace

Result<std::optional<std::string>> WriteTrainingViewSheet(const fs::path& dir, const std::string& run,
                                                          const fs::path& run_dir) {
  const std::vector<fs::path> pairs =
      TrainingViewPairs((run_dir.empty() ? dir / "runs" / run : run_dir) / "renders");
  if (pairs.empty()) return std::optional<std::string>();
  std::vector<Image> rows;
  int width = 0, height = 0;
  for (const fs::path& p : pairs) {
    ICEF_ASSIGN_OR_RETURN(Image image, ReadImage(p));
    image = CompositeOver(image, Vec3f(1, 1, 1));
    width = std::max(width, image.width);
    height += image.height;
    rows.push_back(std::move(image));
  }
  Image sheet(width, height, 3, 1.f);  // white where a narrower row leaves room
  int y0 = 0;
  for (const Image& row : rows) {
    for (int y = 0; y < row.height; ++y)
      std::copy_n(&row.pixels[size_t(y) * row.width * 3], size_t(row.width) * 3,
                  &sheet.pixels[size_t(y0 + y) * width * 3]);
    y0 += row.height;
  }
  const std::string name = "worst_" + run + "_training_views.png";
  ICEF_RETURN_IF_ERROR(WritePng(dir / name, sheet));
  return std::optional<std::string>(name);
}

}  // namespace icef::eval
