#include "icef/face/arkit_curves.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>

namespace icef::face {
namespace {

namespace fs = std::filesystem;

const IctModel& Model() {
  static const std::shared_ptr<const IctModel> model = [] {
    Result<std::shared_ptr<const IctModel>> m = IctModel::LoadDefault();
    EXPECT_TRUE(m.ok()) << m.status().message();
    return *m;
  }();
  return *model;
}

fs::path Write(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("icef_arkit_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(p) << text;
  return p;
}

TEST(ArkitCurves, ReadsLiveLinkFaceLayout) {
  const IctModel& m = Model();
  const fs::path csv = Write("good.csv",
                             "Timecode,BlendShapeCount,EyeBlinkLeft,EyeBlinkRight,JawOpen,MouthSmileLeft,"
                             "BrowInnerUp,TongueOut,HeadYaw\n"
                             "00:00:01:00.000,61,0.1,0.2,0.0,0.5,0.25,0.9,-0.3\n"
                             "00:00:01:01.000,61,1,1,0.8,0,0,0,0.1\n");
  const Result<ArkitCurves> curves = ReadArkitCurves(m, csv);
  fs::remove(csv);
  ASSERT_TRUE(curves.ok()) << curves.status().message();
  ASSERT_EQ(curves->weights.size(), 2u);
  EXPECT_EQ(curves->timecodes[1], "00:00:01:01.000");
  EXPECT_EQ(curves->ignored_columns, (std::vector<std::string>{"TongueOut", "HeadYaw"}));
  // The 51 ARKit names less the five given (BrowInnerUp covers both of ICT's halves).
  EXPECT_EQ(curves->missing_columns.size(), 51u - 5u);
  EXPECT_NE(std::find(curves->missing_columns.begin(), curves->missing_columns.end(), "mouthSmileRight"),
            curves->missing_columns.end());
  EXPECT_EQ(std::find(curves->missing_columns.begin(), curves->missing_columns.end(), "browInnerUp"),
            curves->missing_columns.end());
  const std::vector<float>& w0 = curves->weights[0];
  ASSERT_EQ(w0.size(), size_t(m.num_expressions()));
  EXPECT_FLOAT_EQ(w0[m.ExpressionIndex("eyeBlink_L")], 0.1f);
  EXPECT_FLOAT_EQ(w0[m.ExpressionIndex("eyeBlink_R")], 0.2f);
  EXPECT_FLOAT_EQ(w0[m.ExpressionIndex("mouthSmile_L")], 0.5f);
  EXPECT_FLOAT_EQ(w0[m.ExpressionIndex("mouthSmile_R")], 0.f);
  for (const int e : m.ExpressionTargets("browInnerUp")) EXPECT_FLOAT_EQ(w0[e], 0.25f);  // both halves
  EXPECT_FLOAT_EQ(curves->weights[1][m.ExpressionIndex("jawOpen")], 0.8f);
  // The same weights as the command line's parser gives.
  EXPECT_EQ(curves->weights[1], *ParseArkitExpression(m, "eyeBlinkLeft=1,eyeBlinkRight=1,jawOpen=0.8"));
}

TEST(ArkitCurves, BadFilesAreOneLineNamingTheFileAndLine) {
  const IctModel& m = Model();
  const auto error = [&](const std::string& name, const std::string& text) {
    const fs::path csv = Write(name, text);
    const Result<ArkitCurves> r = ReadArkitCurves(m, csv);
    fs::remove(csv);
    EXPECT_FALSE(r.ok());
    return r.ok() ? std::string() : r.status().message();
  };
  EXPECT_NE(error("empty.csv", "").find(":1: no header"), std::string::npos);
  EXPECT_NE(error("noshape.csv", "Timecode,HeadYaw\n0,1\n").find("no blendshape column"), std::string::npos);
  EXPECT_NE(error("twice.csv", "JawOpen,jawOpen\n0,1\n").find("sets jawOpen"), std::string::npos);
  const std::string width = error("width2.csv", "Timecode,JawOpen\n0,0.5\n1\n");
  EXPECT_NE(width.find("width2.csv:3: 1 cells, the header has 2"), std::string::npos) << width;
  const std::string nan = error("nan.csv", "Timecode,JawOpen\n0,abc\n");
  EXPECT_NE(nan.find("nan.csv:2: JawOpen: 'abc' is not a finite number"), std::string::npos) << nan;
  EXPECT_NE(error("noframes.csv", "Timecode,JawOpen\n").find("no frames"), std::string::npos);
  EXPECT_NE(ReadArkitCurves(m, "/nonexistent/x.csv").status().message().find("cannot read"),
            std::string::npos);
}

}  // namespace
}  // namespace icef::face
