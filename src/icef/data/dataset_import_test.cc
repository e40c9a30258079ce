#include "icef/data/dataset_import.h"

#include <gtest/gtest.h>

#include <map>

#include "icef/io/atomic_file.h"
#include "icef/io/json_util.h"
#include "icef/testing/tiny_dataset.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

std::map<std::string, std::string> Snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[e.path().string()] = ReadFile(e.path()).value();
  return files;
}

TEST(DatasetImport, FormatNamesRoundTrip) {
  for (DatasetFormat f :
       {DatasetFormat::kAuto, DatasetFormat::kIcef, DatasetFormat::kNerface, DatasetFormat::kInstantNgp})
    EXPECT_EQ(ParseDatasetFormat(DatasetFormatName(f)), f);
  EXPECT_FALSE(ParseDatasetFormat("colmap").has_value());
}

TEST(DatasetImport, DetectsTheLayout) {
  const fs::path root = testing::MakeTempDir("import_detect");
  testing::WriteTinyNerfaceDataset(root / "nerface");
  testing::WriteTinyDataset(root / "ours");
  testing::TinyDatasetOptions ngp;
  ngp.expression_dim = 0;
  testing::WriteTinyDataset(root / "ngp", ngp);
  Json doc = ReadJsonFile(root / "ngp" / "transforms_train.json").value();
  doc.erase("expression_dim");
  ASSERT_TRUE(WriteFileAtomic(root / "ngp" / "transforms_train.json", doc.dump()).ok());
  EXPECT_EQ(DetectDatasetFormat(root / "nerface").value(), DatasetFormat::kNerface);
  EXPECT_EQ(DetectDatasetFormat(root / "ours").value(), DatasetFormat::kIcef);
  EXPECT_EQ(DetectDatasetFormat(root / "ngp").value(), DatasetFormat::kInstantNgp);
  EXPECT_FALSE(DetectDatasetFormat(root / "missing").ok());
}

TEST(DatasetImport, ConvertsANerfaceDataset) {
  const fs::path root = testing::MakeTempDir("import_nerface");
  const testing::TinyNerfaceInfo info = testing::WriteTinyNerfaceDataset(root / "src");
  const auto source_files = Snapshot(root / "src");
  const Dataset source = LoadDataset(root / "src").value();

  const Result<ImportReport> report = ImportDataset(root / "src", root / "dst", ImportOptions{});
  ASSERT_TRUE(report.ok()) << report.status().message();
  EXPECT_EQ(report->format, DatasetFormat::kNerface);
  EXPECT_EQ(report->images, 3 + 1 + 1 + 1);
  EXPECT_EQ(Snapshot(root / "src"), source_files);  // the source is untouched

  // Our format now: explicit w/h, fl_x, expression_dim, background colour and image.
  const Json train = ReadJsonFile(root / "dst" / "transforms_train.json").value();
  EXPECT_EQ(train["w"], 8);
  EXPECT_EQ(train["expression_dim"], 76);
  EXPECT_EQ(train["background_file_path"], "background.png");
  EXPECT_FALSE(train.contains("intrinsics"));

  const Dataset d = LoadDataset(root / "dst").value();
  ASSERT_EQ(d.train.size(), source.train.size());
  ASSERT_EQ(d.val.size(), 1u);
  ASSERT_EQ(d.test.size(), 1u);
  EXPECT_EQ(d.train[1].file_path, "images/train_0001.png");
  EXPECT_EQ(d.val[0].file_path, "images/val_0000.png");
  for (size_t i = 0; i < d.train.size(); ++i) {
    EXPECT_EQ(d.train[i].expression, source.train[i].expression);
    EXPECT_EQ(d.train[i].camera.world_from_cam(), source.train[i].camera.world_from_cam());
    EXPECT_EQ(d.train[i].camera.intrinsics().fl_x, info.intrinsics[0]);
    EXPECT_EQ(d.train[i].camera.intrinsics().cx, source.train[i].camera.intrinsics().cx);
    EXPECT_EQ(d.train[i].bbox, source.train[i].bbox);
    EXPECT_EQ(ReadFile(d.ImagePath(d.train[i])).value(), ReadFile(source.ImagePath(source.train[i])).value());
  }
  EXPECT_LT((d.background - info.background_mean).cwiseAbs().maxCoeff(), 1e-6f);
  EXPECT_EQ(ReadFile(root / "dst" / "background.png").value(),
            ReadFile(root / "src" / "bg" / "00050.png").value());
  EXPECT_EQ(report->dataset.root, root / "dst");
}

TEST(DatasetImport, NerfaceNegativeFocalLengthsKeepTheirRays) {
  // real_to_nerf.py's fx, fy < 0, and two mirrored train frames (one negative focal each): our
  // format, reloaded, casts NerFace's rays through every pixel, and projects back onto them.
  const fs::path root = testing::MakeTempDir("import_signed_focals");
  testing::TinyNerfaceOptions options;
  options.signed_focals = true;
  testing::WriteTinyNerfaceDataset(root / "src", options);
  const Result<ImportReport> report = ImportDataset(root / "src", root / "dst", ImportOptions{});
  ASSERT_TRUE(report.ok()) << report.status().message();
  const Dataset d = LoadDataset(root / "dst").value();
  EXPECT_FALSE(ReadJsonFile(root / "dst" / "transforms_train.json").value().contains("intrinsics"));
  for (const auto& [split, frames] :
       {std::pair{"train", &d.train}, std::pair{"val", &d.val}, std::pair{"test", &d.test}}) {
    const Json source = ReadJsonFile(root / "src" / ("transforms_" + std::string(split) + ".json")).value();
    ASSERT_EQ(frames->size(), source["frames"].size());
    for (size_t f = 0; f < frames->size(); ++f) {
      const Camera& camera = (*frames)[f].camera;
      for (int j = 0; j < camera.height(); ++j) {
        for (int i = 0; i < camera.width(); ++i) {
          SCOPED_TRACE(std::string(split) + " frame " + std::to_string(f) + " pixel (" + std::to_string(i) +
                       ", " + std::to_string(j) + ")");
          const testing::RayD expected =
              testing::NerfaceRay(source, int(f), camera.width(), camera.height(), i, j);
          const Ray ray = camera.PixelRay(i, j);
          EXPECT_LT((ray.origin.cast<double>() - expected.origin).norm(), 1e-6);
          EXPECT_LT((ray.direction.cast<double>().normalized() - expected.direction).norm(), 1e-6);
          const auto projection = camera.Project(expected.origin + 1.5 * expected.direction);
          ASSERT_TRUE(projection.has_value());
          EXPECT_NEAR(projection->uv.x(), i + 0.5, 1e-9);
          EXPECT_NEAR(projection->uv.y(), j + 0.5, 1e-9);
        }
      }
    }
  }
}

TEST(DatasetImport, HardLinksWhenAsked) {
  const fs::path root = testing::MakeTempDir("import_link");
  testing::WriteTinyNerfaceDataset(root / "src");
  ImportOptions options;
  options.link_images = true;
  ASSERT_TRUE(ImportDataset(root / "src", root / "dst", options).ok());
  EXPECT_GE(fs::hard_link_count(root / "dst" / "images" / "train_0000.png"), 2u);
}

TEST(DatasetImport, RefusesANonEmptyDestinationAndTouchesNothing) {
  const fs::path root = testing::MakeTempDir("import_busy");
  testing::WriteTinyNerfaceDataset(root / "src");
  fs::create_directories(root / "dst");
  ASSERT_TRUE(WriteFileAtomic(root / "dst" / "keep.txt", "mine").ok());
  const auto before = Snapshot(root);
  const auto result = ImportDataset(root / "src", root / "dst", ImportOptions{});
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("not an empty directory"), std::string::npos);
  EXPECT_EQ(Snapshot(root), before);
}

TEST(DatasetImport, InvalidSourceLeavesNoDestination) {
  const fs::path root = testing::MakeTempDir("import_invalid");
  testing::WriteTinyNerfaceDataset(root / "src");
  fs::remove(root / "src" / "train" / "f_0002.png");
  const auto result = ImportDataset(root / "src", root / "dst", ImportOptions{});
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("transforms_train.json: frames[2].file_path: image not found"),
            std::string::npos)
      << result.status().message();
  EXPECT_FALSE(fs::exists(root / "dst"));
  for (const auto& e : fs::directory_iterator(root)) EXPECT_EQ(e.path().filename(), "src");  // no temp left
}

TEST(DatasetImport, NerfaceFormatNeedsExpressions) {
  const fs::path root = testing::MakeTempDir("import_noexpr");
  testing::TinyDatasetOptions options;
  options.expression_dim = 0;
  testing::WriteTinyDataset(root / "src", options);
  ImportOptions import;
  import.format = DatasetFormat::kNerface;
  const auto result = ImportDataset(root / "src", root / "dst", import);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("frames[0].expression: missing"), std::string::npos);
  import.format = DatasetFormat::kInstantNgp;
  const auto ok = ImportDataset(root / "src", root / "dst", import);
  ASSERT_TRUE(ok.ok()) << ok.status().message();
  EXPECT_EQ(ok->dataset.expression_dim, 0);
}

}  // namespace
}  // namespace icef
