// RunSynth / RunLandmarks option checks, made before anything is rendered or read.
#include "icef/app/synth_app.h"

#include <gtest/gtest.h>

#include <sstream>

#include "icef/app/landmarks_app.h"
#include "icef/testing/tiny_dataset.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

TEST(SynthApp, PhotoModeOptionsAreChecked) {
  SynthAppOptions o;
  EXPECT_NE(o.Validate().message().find("--out"), std::string::npos);
  o.out = testing::MakeTempDir("synth_app_photos") / "photos";
  o.photos = 2;
  o.contact_sheet = "sheet.png";
  EXPECT_NE(o.Validate().message().find("--contact-sheet"), std::string::npos) << o.Validate().message();
  o.contact_sheet.clear();
  o.photo_size = "480by640";
  std::ostringstream out;
  const Status s = RunSynth(o, Executor(1), out);
  EXPECT_EQ(s.message(), "--res-photo: expected WxH (e.g. 480x640), got '480by640'");
  EXPECT_FALSE(fs::exists(o.out));
}

TEST(LandmarksApp, BadSplitsNameTheOption) {
  LandmarksAppOptions o;
  o.dataset = "data";
  o.splits = {"train", "tset"};
  EXPECT_EQ(o.Validate().message(), "--splits: splits: unknown split \"tset\" (expected train, test or val)");
  std::ostringstream out;
  EXPECT_FALSE(RunLandmarks(o, Executor(1), out).ok());
  o.splits = {"train"};
  EXPECT_TRUE(o.Validate().ok());
}

}  // namespace
}  // namespace icef
