#include "icef/app/curves_app.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "icef/face/arkit_curves.h"
#include "icef/io/atomic_file.h"
#include "icef/testing/tiny_dataset.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

// What icef track --curves writes, face::ReadArkitCurves reads back: every weight (a split pair as
// the mean of its halves, on both), the timecodes at the frame rate, the head's angles as columns
// the reader lists and ignores.
TEST(ArkitCurvesCsv, ReadsBackAsTheWeightsItWrote) {
  const face::IctModel& ict = **face::IctModel::LoadDefault();
  const int n = ict.num_expressions();
  std::vector<CurveFrame> frames(3);
  for (int f = 0; f < 3; ++f) {
    frames[f].time_s = f / 30.0 + (f == 2 ? 1.0 : 0.0);
    frames[f].weights.resize(n);
    for (int e = 0; e < n; ++e) frames[f].weights[e] = float((e * 7 + f * 3) % 11) / 10.f;
    frames[f].yaw = 0.1 * f, frames[f].pitch = -0.05, frames[f].roll = 0.02;
  }
  const fs::path dir = testing::MakeTempDir("curves_csv");
  const std::string text = ArkitCurvesCsv(ict, frames, 30);
  ASSERT_TRUE(WriteFileAtomic(dir / "c.csv", text).ok());
  EXPECT_EQ(text.substr(0, 25), "Timecode,BlendShapeCount,");
  EXPECT_NE(text.find(",EyeBlinkLeft,"), std::string::npos);
  const Result<face::ArkitCurves> back = face::ReadArkitCurves(ict, dir / "c.csv");
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_EQ(back->weights.size(), 3u);
  EXPECT_EQ(back->timecodes[0], "00:00:00:00.000");
  EXPECT_EQ(back->timecodes[1], "00:00:00:01.000");
  EXPECT_EQ(back->timecodes[2], "00:00:01:02.000");
  EXPECT_EQ(back->ignored_columns, (std::vector<std::string>{"HeadYaw", "HeadPitch", "HeadRoll"}));
  for (const std::string& name : ict.ArkitNames()) {
    const std::vector<int> t = ict.ExpressionTargets(name);
    for (int f = 0; f < 3; ++f) {
      float mean = 0;
      for (int e : t) mean += frames[f].weights[e] / t.size();
      for (int e : t) EXPECT_NEAR(back->weights[f][e], mean, 1e-4) << name << " frame " << f;
    }
  }
  std::istringstream lines(text);
  std::string header, row;
  std::getline(lines, header);
  std::getline(lines, row);
  EXPECT_EQ(header.substr(header.size() - 26), "HeadYaw,HeadPitch,HeadRoll");
  EXPECT_EQ(row.substr(row.size() - 25), ",0.00000,-0.05000,0.02000");
  EXPECT_EQ(std::count(row.begin(), row.end(), ','), std::count(header.begin(), header.end(), ','));
}

}  // namespace
}  // namespace icef
