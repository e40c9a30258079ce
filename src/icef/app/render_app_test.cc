// RunRender with --set overrides: inference-only model keys change the render, keys fixed by
// training are refused before anything is written.
#include "icef/app/render_app.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "icef/app/app_test_util.h"
#include "icef/face/ict_model.h"
#include "icef/io/image.h"
#include "icef/video/video_reader.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

TEST(RenderApp, InferenceOverrideApplies) {
  const fs::path dir = testing::MakeTempDir("render_app_override");
  RenderAppOptions o;
  o.model = testing_app::WriteTinyModelDir(dir / "model");
  o.out = dir / "out";
  o.threads = 1;
  o.overrides = {"model.render.supersample=1", "model.bf16_inference=false"};
  std::ostringstream out;
  const Result<std::vector<RenderedFrameInfo>> frames = RunRender(o, out);
  ASSERT_TRUE(frames.ok()) << frames.status().message();
  ASSERT_EQ(frames->size(), 1u);
  const Result<Image> color = ReadImage(o.out / "color_000.png");
  ASSERT_TRUE(color.ok()) << color.status().message();
  EXPECT_EQ(color->width, 16);
  EXPECT_NE(out.str().find("frame 000: delta"), std::string::npos) << out.str();
}

// --video: the sequence's colour frames as an MP4 that the video reader reads back, frame for frame;
// an odd image height is padded to even (H.264 needs it).
TEST(RenderApp, OrbitVideoReadsBack) {
  const fs::path dir = testing::MakeTempDir("render_app_video");
  RenderAppOptions o;
  o.model = testing_app::WriteTinyModelDir(dir / "model");
  o.out = dir / "out";
  o.threads = 1;
  o.orbit = 6;
  o.resolution = 15;
  o.video = dir / "orbit.mp4";
  o.fps = 12;
  std::ostringstream out;
  const Result<std::vector<RenderedFrameInfo>> frames = RunRender(o, out);
  ASSERT_TRUE(frames.ok()) << frames.status().message();
  const Result<VideoInfo> info = ProbeVideo(*o.video);
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->height, 16);
  EXPECT_EQ(info->width % 2, 0);
  EXPECT_NEAR(info->fps, 12, 1e-6);
  const Result<std::vector<VideoFrame>> decoded = ReadVideoFrames(*o.video, {});
  ASSERT_TRUE(decoded.ok()) << decoded.status().message();
  EXPECT_EQ(decoded->size(), 6u);
  EXPECT_NE(out.str().find("video: "), std::string::npos) << out.str();
  // A bad frame rate is refused before anything is written.
  o.fps = 0;
  o.video = dir / "bad.mp4";
  EXPECT_FALSE(RunRender(o, out).ok());
  EXPECT_FALSE(fs::exists(dir / "bad.mp4"));
}

TEST(RenderApp, ArchitectureOverrideIsRefused) {
  const fs::path dir = testing::MakeTempDir("render_app_refuse");
  RenderAppOptions o;
  o.model = testing_app::WriteTinyModelDir(dir / "model");
  o.out = dir / "out";
  o.threads = 1;
  o.overrides = {"model.static_field.grid.log2_table_size=12"};
  std::ostringstream out;
  const Status s = RunRender(o, out).status();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("model.static_field.grid.log2_table_size cannot be changed on a trained model"),
            std::string::npos)
      << s.message();
  EXPECT_FALSE(fs::exists(o.out / "color_000.png"));
}

// --expression and --expressions (ARKit names): a model in ICT-FaceKit's expression space is driven by a
// Live Link Face CSV, one frame per row; a model in another space refuses both, naming the option.
TEST(RenderApp, ArkitCurvesDriveAnIctSpaceModel) {
  const fs::path dir = testing::MakeTempDir("render_app_arkit");
  const face::IctModel& ict = **face::IctModel::LoadDefault();
  ModelSetup setup = testing_model::TinySetup(ict.num_expressions());
  setup.expression_names = ict.expression_names();
  RenderAppOptions o;
  o.model = testing_app::WriteTinyModelDir(dir / "model", setup);
  o.out = dir / "out";
  o.threads = 1;
  o.arkit_curves = dir / "curves.csv";
  {
    std::ofstream csv(*o.arkit_curves);
    csv << "Timecode,BlendShapeCount,JawOpen,EyeBlinkLeft,EyeBlinkRight,MouthSmileLeft,HeadYaw\n";
    for (int i = 0; i < 3; ++i) csv << "00:00:00:0" << i << ".000,61," << 0.4 * i << ",0,0,0.5,0\n";
  }
  std::ostringstream out;
  const Result<std::vector<RenderedFrameInfo>> frames = RunRender(o, out);
  ASSERT_TRUE(frames.ok()) << frames.status().message();
  EXPECT_EQ(frames->size(), 3u);
  EXPECT_TRUE(fs::exists(o.out / "color_002.png"));
  // One expression by name; a CSV beside it is refused.
  o.out = dir / "one";
  o.arkit_expression = "jawOpen=1,mouthSmileLeft=0.5,mouthSmileRight=0.5";
  EXPECT_NE(RunRender(o, out).status().message().find("--expressions: the CSV gives"), std::string::npos);
  o.arkit_curves.reset();
  const Result<std::vector<RenderedFrameInfo>> one = RunRender(o, out);
  ASSERT_TRUE(one.ok()) << one.status().message();
  EXPECT_EQ(one->size(), 1u);
  o.arkit_expression = "jawOpen=1,noSuchShape=1";
  EXPECT_NE(RunRender(o, out).status().message().find("unknown expression 'noSuchShape'"), std::string::npos);

  // The tiny model's own expression space knows no ARKit names.
  RenderAppOptions other;
  other.model = testing_app::WriteTinyModelDir(dir / "other");
  other.out = dir / "other_out";
  other.threads = 1;
  other.arkit_expression = "jawOpen=1";
  EXPECT_NE(RunRender(other, out).status().message().find("--expression: ARKit names need"),
            std::string::npos);
}

}  // namespace
}  // namespace icef
