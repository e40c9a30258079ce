#include "icef/study/training_view_sheet.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "icef/io/image.h"

namespace icef::eval {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("icef_sheet_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// A w x h RGB image whose every pixel holds `value` in red.
Image Flat(int w, int h, float value) {
  Image image(w, h, 3, 0.f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) image.At(x, y, 0) = value;
  return image;
}

TEST(TrainingViewSheetTest, StacksTheRunsPairsInFrameOrder) {
  const fs::path dir = TempDir("stack");
  const fs::path renders = dir / "runs" / "id101_k5_icef" / "renders";
  fs::create_directories(renders);
  // Written out of order; a narrower pair, and files that are not training-view pairs.
  ASSERT_TRUE(WritePng(renders / "fit_train_001_vs_truth.png", Flat(6, 2, 0.6f)).ok());
  ASSERT_TRUE(WritePng(renders / "fit_train_000_vs_truth.png", Flat(8, 3, 0.2f)).ok());
  ASSERT_TRUE(WritePng(renders / "fit_train_000.png", Flat(4, 3, 1.f)).ok());
  ASSERT_TRUE(WritePng(renders / "test_000.png", Flat(4, 3, 1.f)).ok());

  const Result<std::optional<std::string>> sheet = WriteTrainingViewSheet(dir, "id101_k5_icef");
  ASSERT_TRUE(sheet.ok()) << sheet.status().message();
  ASSERT_TRUE(sheet->has_value());
  EXPECT_EQ(**sheet, "worst_id101_k5_icef_training_views.png");
  const Result<Image> image = ReadImage(dir / **sheet);
  ASSERT_TRUE(image.ok());
  ASSERT_EQ(image->width, 8);
  ASSERT_EQ(image->height, 5);
  EXPECT_NEAR(image->At(7, 2, 0), 0.2f, 1.f / 255);  // frame 000 on top
  EXPECT_NEAR(image->At(0, 3, 0), 0.6f, 1.f / 255);  // then frame 001
  EXPECT_NEAR(image->At(7, 4, 0), 1.f, 1.f / 255);   // white beside the narrower pair
  EXPECT_NEAR(image->At(7, 4, 1), 1.f, 1.f / 255);
  fs::remove_all(dir);
}

TEST(TrainingViewSheetTest, NoRendersNoSheetAndAnUnreadableOneNamesTheFile) {
  const fs::path dir = TempDir("none");
  const Result<std::optional<std::string>> none = WriteTrainingViewSheet(dir, "id1_k5_icef");
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(none->has_value());
  EXPECT_TRUE(fs::is_empty(dir));

  const fs::path renders = dir / "runs" / "id1_k5_icef" / "renders";
  fs::create_directories(renders);
  std::ofstream(renders / "fit_train_000_vs_truth.png") << "not a png";
  const Result<std::optional<std::string>> bad = WriteTrainingViewSheet(dir, "id1_k5_icef");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("fit_train_000_vs_truth.png"), std::string::npos)
      << bad.status().message();
  EXPECT_FALSE(fs::exists(dir / "worst_id1_k5_icef_training_views.png"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace icef::eval
