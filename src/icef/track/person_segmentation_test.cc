#include "icef/track/person_segmentation.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "icef/io/image.h"

namespace icef::track {
namespace {

namespace fs = std::filesystem;

TEST(PersonSegmenterTest, MissingModelIsAnErrorNamingTheFile) {
  auto missing = PersonSegmenter::Load(fs::temp_directory_path() / "icef_no_selfie_model");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("icef_no_selfie_model/selfie.json"), std::string::npos)
      << missing.status().message();
  EXPECT_NE(missing.status().message().find("install-deps"), std::string::npos);
}

// The astronaut photo (python3-skimage, installed by install-deps.sh): her face and suit are the
// person, the wall behind her head is not.
TEST(PersonSegmenterTest, FindsThePersonInARealPhoto) {
  const fs::path photo = "/usr/lib/python3/dist-packages/skimage/data/astronaut.png";
  if (!fs::exists(fs::path(kDefaultSelfieDir) / "selfie.json") || !fs::exists(photo))
    GTEST_SKIP() << "segmentation model or the astronaut photo not installed";
  auto segmenter = PersonSegmenter::Load();
  ASSERT_TRUE(segmenter.ok()) << segmenter.status().message();
  auto image = ReadImage(photo);
  ASSERT_TRUE(image.ok()) << image.status().message();
  auto p = segmenter->Run(*image);
  ASSERT_TRUE(p.ok()) << p.status().message();
  ASSERT_EQ(p->width, 512);
  ASSERT_EQ(p->height, 512);
  ASSERT_EQ(p->channels, 1);
  EXPECT_GT(p->At(225, 125, 0), 0.9f);  // her face (between the eyes and the mouth)
  EXPECT_GT(p->At(240, 400, 0), 0.9f);  // her suit
  EXPECT_LT(p->At(40, 40, 0), 0.05f);   // the wall, top left
  EXPECT_LT(p->At(470, 60, 0), 0.05f);  // the wall, top right
  double person = 0;
  for (float v : p->pixels) person += v > 0.5f;
  // About half of the photo: the seated figure (0.545 of it as TF.js segments it).
  EXPECT_NEAR(person / (512.0 * 512.0), 0.545, 0.03);
  auto gray = segmenter->Run(Image(8, 8, 1));
  EXPECT_FALSE(gray.ok());
}

}  // namespace
}  // namespace icef::track
