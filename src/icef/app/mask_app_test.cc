// RunMask on a tiny dataset: the overlay, projection and slice PNGs are written and listed; a
// --frame outside the training frames is refused naming the count.
#include "icef/app/mask_app.h"

#include <gtest/gtest.h>

#include <sstream>

#include "icef/io/image.h"
#include "icef/testing/tiny_dataset.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

MaskAppOptions TinyMask(const std::string& name) {
  const fs::path dir = testing::MakeTempDir(name);
  testing::TinyDatasetOptions d;
  d.width = 32;
  d.height = 24;
  d.landmarks_3d = true;
  testing::WriteTinyDataset(dir / "data", d);
  MaskAppOptions o;
  o.dataset = dir / "data";
  o.out = dir / "mask";
  return o;
}

TEST(MaskApp, WritesAndListsItsPngs) {
  MaskAppOptions o = TinyMask("mask_app_pngs");
  o.frame = 1;
  std::ostringstream out;
  const Status s = RunMask(o, Executor(1), out);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(out.str().rfind("mask: ", 0), 0u) << out.str();
  for (const char* name : {"mask_overlay_frame1.png", "mask_projection_frame1.png", "mask_slice_xy.png",
                           "mask_slice_xz.png", "mask_slice_yz.png"}) {
    const fs::path path = o.out / name;
    EXPECT_TRUE(fs::exists(path)) << path;
    EXPECT_NE(out.str().find(path.string() + "\n"), std::string::npos) << out.str();
  }
  const Result<Image> overlay = ReadImage(o.out / "mask_overlay_frame1.png");
  ASSERT_TRUE(overlay.ok()) << overlay.status().message();
  EXPECT_EQ(overlay->width, 32);
  EXPECT_EQ(overlay->height, 24);
  EXPECT_FALSE(fs::exists(o.out / "fit_frame1.png"));  // e0, e1, ...: not the face model's expressions
}

TEST(MaskApp, FrameOutOfRangeIsRefused) {
  for (const int frame : {3, -1}) {
    MaskAppOptions o = TinyMask("mask_app_frame");
    o.frame = frame;
    std::ostringstream out;
    const Status s = RunMask(o, Executor(1), out);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.message(),
              "--frame " + std::to_string(frame) + " is out of range: the dataset has 3 training frames");
    EXPECT_FALSE(fs::exists(o.out));
  }
}

TEST(MaskApp, OptionsNeedADatasetAndAnOutputDirectory) {
  MaskAppOptions o;
  EXPECT_FALSE(o.Validate().ok());
  o.dataset = "d";
  EXPECT_NE(o.Validate().message().find("--out"), std::string::npos);
  o.out = "o";
  EXPECT_TRUE(o.Validate().ok());
}

}  // namespace
}  // namespace icef
