#include "icef/face/ict_model.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>

namespace icef::face {
namespace {

namespace fs = std::filesystem;

// Counts scripts/convert_ict_facekit.py printed for ICT-FaceKit da5f95a (its README agrees).
constexpr int kVertices = 26719, kTriangles = 52220, kUvs = 28911;

// The model at DefaultPath(), loaded once; nullptr when the file is absent (tests skip).
const IctModel* Model() {
  static const Result<IctModel>* loaded = [] {
    const fs::path path = IctModel::DefaultPath();
    return fs::exists(path) ? new Result<IctModel>(IctModel::Load(path)) : nullptr;
  }();
  if (loaded == nullptr) return nullptr;
  EXPECT_TRUE(loaded->ok()) << loaded->status().message();
  return loaded->ok() ? &loaded->value() : nullptr;
}

#define ICT_MODEL_OR_SKIP(m)                                                              \
  const IctModel* m##_ptr = Model();                                                      \
  if (m##_ptr == nullptr) GTEST_SKIP() << "no face model at " << IctModel::DefaultPath(); \
  const IctModel& m = *m##_ptr

std::vector<float> Weights(const IctModel& m, std::string_view text) {
  auto w = ParseArkitExpression(m, text);
  EXPECT_TRUE(w.ok()) << w.status().message();
  return w.ok() ? *w : std::vector<float>(m.num_expressions(), 0.f);
}

// A scratch directory for this test process.
fs::path ScratchDir() {
  const fs::path dir = fs::temp_directory_path() / ("icef_ict_model_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

fs::path WriteFile(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(IctModel, LoadsTheCountsOfTheSource) {
  ICT_MODEL_OR_SKIP(m);
  EXPECT_EQ(m.num_vertices(), kVertices);
  EXPECT_EQ(static_cast<int>(m.triangles().size()), kTriangles);
  EXPECT_EQ(static_cast<int>(m.uvs().size()), kUvs);
  EXPECT_EQ(m.triangle_uvs().size(), m.triangles().size());
  EXPECT_EQ(m.num_identities(), 100);
  EXPECT_EQ(m.num_expressions(), 53);
  EXPECT_EQ(m.source_commit().size(), 40u);
  for (int32_t v : m.landmark_vertices()) EXPECT_GE(v, 0);  // ICT has all 68
  EXPECT_EQ(m.landmark_vertices()[0], 1225);
  EXPECT_EQ(m.landmark_vertices()[30], 4857);  // nose tip
  EXPECT_NE(m.ToString().find("vertices=26719"), std::string::npos) << m.ToString();
}

TEST(IctModel, ExpressionsAreTheArkitNames) {
  ICT_MODEL_OR_SKIP(m);
  // ARKit's 52 blendshapes, less tongueOut; ICT splits browInnerUp and cheekPuff.
  const std::vector<std::string> arkit = {
      "browDownLeft",      "browDownRight",      "browInnerUp",         "browOuterUpLeft",
      "browOuterUpRight",  "cheekPuff",          "cheekSquintLeft",     "cheekSquintRight",
      "eyeBlinkLeft",      "eyeBlinkRight",      "eyeLookDownLeft",     "eyeLookDownRight",
      "eyeLookInLeft",     "eyeLookInRight",     "eyeLookOutLeft",      "eyeLookOutRight",
      "eyeLookUpLeft",     "eyeLookUpRight",     "eyeSquintLeft",       "eyeSquintRight",
      "eyeWideLeft",       "eyeWideRight",       "jawForward",          "jawLeft",
      "jawOpen",           "jawRight",           "mouthClose",          "mouthDimpleLeft",
      "mouthDimpleRight",  "mouthFrownLeft",     "mouthFrownRight",     "mouthFunnel",
      "mouthLeft",         "mouthLowerDownLeft", "mouthLowerDownRight", "mouthPressLeft",
      "mouthPressRight",   "mouthPucker",        "mouthRight",          "mouthRollLower",
      "mouthRollUpper",    "mouthShrugLower",    "mouthShrugUpper",     "mouthSmileLeft",
      "mouthSmileRight",   "mouthStretchLeft",   "mouthStretchRight",   "mouthUpperUpLeft",
      "mouthUpperUpRight", "noseSneerLeft",      "noseSneerRight"};
  ASSERT_EQ(arkit.size(), 51u);
  std::vector<std::string> covered = m.ArkitNames(), expected = arkit;
  std::sort(covered.begin(), covered.end());
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(covered, expected);
  std::vector<int> hits(m.num_expressions(), 0);
  for (const std::string& name : arkit) {
    const std::vector<int> targets = m.ExpressionTargets(name);
    ASSERT_FALSE(targets.empty()) << name;
    EXPECT_EQ(targets.size(), name == "browInnerUp" || name == "cheekPuff" ? 2u : 1u) << name;
    for (int e : targets) ++hits[e];
  }
  for (int e = 0; e < m.num_expressions(); ++e) EXPECT_EQ(hits[e], 1) << m.expression_names()[e];
  EXPECT_EQ(m.ExpressionIndex("mouthSmile_L"), m.ExpressionIndex("mouthSmileLeft"));
  EXPECT_EQ(m.expression_names()[m.ExpressionIndex("eyeBlinkRight")], "eyeBlink_R");
  EXPECT_EQ(m.expression_names()[m.ExpressionIndex("mouthLeft")], "mouthLeft");  // unsided
  EXPECT_EQ(m.ExpressionIndex("JawOpen"), m.ExpressionIndex("jawOpen"));         // Live Link Face case
  EXPECT_EQ(m.ExpressionIndex("browInnerUp"), -1);  // a split pair: ExpressionTargets gives both
  EXPECT_EQ(m.ExpressionIndex("tongueOut"), -1);
  EXPECT_EQ(m.ExpressionIndex("smile"), -1);
}

TEST(IctModel, ZeroCoefficientsGiveTheNeutralExactly) {
  ICT_MODEL_OR_SKIP(m);
  const std::vector<float> id(m.num_identities(), 0.f), ex(m.num_expressions(), 0.f);
  EXPECT_EQ(m.Mesh(id, ex), m.neutral());
  EXPECT_EQ(m.Mesh({}, {}), m.neutral());
}

TEST(IctModel, MeshIsLinearInTheCoefficients) {
  ICT_MODEL_OR_SKIP(m);
  std::mt19937 rng(7);
  std::normal_distribution<float> normal(0.f, 1.f);
  std::uniform_real_distribution<float> uniform(0.f, 0.5f);
  std::vector<float> id(m.num_identities()), ex(m.num_expressions());
  for (float& c : id) c = normal(rng);
  for (float& w : ex) w = uniform(rng);
  std::vector<float> id2 = id, ex2 = ex;
  for (float& c : id2) c *= 2;
  for (float& w : ex2) w *= 2;
  const auto& n = m.neutral();
  const auto a = m.Mesh(id, ex), a2 = m.Mesh(id2, ex2), a_id = m.Mesh(id, {}), a_ex = m.Mesh({}, ex);
  float scale_err = 0, sum_err = 0, moved = 0;
  for (int v = 0; v < m.num_vertices(); ++v) {
    scale_err = std::max(scale_err, ((a2[v] - n[v]) - 2 * (a[v] - n[v])).norm());
    sum_err = std::max(sum_err, ((a[v] - n[v]) - (a_id[v] - n[v]) - (a_ex[v] - n[v])).norm());
    moved = std::max(moved, (a[v] - n[v]).norm());
  }
  EXPECT_GT(moved, 1.f);        // cm: the coefficients do something
  EXPECT_LT(scale_err, 1e-5f);  // float round-off at |x| ~ 20 cm
  EXPECT_LT(sum_err, 1e-5f);
  // One coefficient: the mode itself.
  ex.assign(m.num_expressions(), 0.f);
  const int jaw = m.ExpressionIndex("jawOpen");
  ex[jaw] = 1.f;
  const auto open = m.Mesh({}, ex);
  const auto delta = m.ExpressionDelta(jaw);
  float mode_err = 0;
  for (int v = 0; v < m.num_vertices(); ++v)
    mode_err = std::max(mode_err, (open[v] - n[v] - delta[v]).norm());
  EXPECT_LT(mode_err, 1e-5f);
}

TEST(IctModel, JawOpenLowersTheChinAndLeavesTheForeheadStill) {
  ICT_MODEL_OR_SKIP(m);
  const auto neutral_lm = m.Landmarks(m.neutral());
  const auto open = m.Mesh({}, Weights(m, "jawOpen=1"));
  const auto open_lm = m.Landmarks(open);
  const Vec3f chin = open_lm[8] - neutral_lm[8];   // iBUG 8: chin
  EXPECT_LT(chin.y(), -1.5f) << chin.transpose();  // cm down
  EXPECT_GT(chin.y(), -4.f) << chin.transpose();
  EXPECT_LT(chin.z(), 0.f) << chin.transpose();  // and back, about the jaw hinge
  EXPECT_LT(std::abs(chin.x()), 1e-3f);
  // Forehead: face vertices 1.5 cm above the brow landmarks (19, 24).
  const float brow_y = std::max(neutral_lm[19].y(), neutral_lm[24].y());
  const int face = m.PartIndex("face");
  int count = 0;
  float forehead_move = 0;
  for (int v = 0; v < m.num_vertices(); ++v) {
    if (m.part_labels()[v] != face || m.neutral()[v].y() < brow_y + 1.5f) continue;
    ++count;
    forehead_move = std::max(forehead_move, (open[v] - m.neutral()[v]).norm());
  }
  EXPECT_GT(count, 100);
  EXPECT_LT(forehead_move, 0.05f * std::abs(chin.y()));
}

TEST(IctModel, EyeBlinkLeftClosesTheSubjectsLeftEye) {
  ICT_MODEL_OR_SKIP(m);
  const auto n = m.Landmarks(m.neutral());
  // iBUG 42-47 are the subject's left eye (+x), 36-41 the right.
  EXPECT_GT(n[42].x(), 0.f);
  EXPECT_LT(n[39].x(), 0.f);
  const auto blink = m.Landmarks(m.Mesh({}, Weights(m, "eyeBlink_L=1")));
  const auto gap = [](const std::vector<Vec3f>& lm, int upper, int lower) {
    return (lm[upper] - lm[lower]).norm();
  };
  for (const auto& [upper, lower] : {std::pair{43, 47}, {44, 46}}) {
    EXPECT_GT(gap(n, upper, lower), 0.5f);  // cm, open
    EXPECT_LT(gap(blink, upper, lower), 0.25f * gap(n, upper, lower)) << upper << "-" << lower;
  }
  for (const auto& [upper, lower] : {std::pair{37, 41}, {38, 40}})
    EXPECT_NEAR(gap(blink, upper, lower), gap(n, upper, lower), 1e-3f) << upper << "-" << lower;
}

TEST(IctModel, FrameAndPartsAreAsDocumented) {
  ICT_MODEL_OR_SKIP(m);
  const auto lm = m.Landmarks(m.neutral());
  EXPECT_LT(lm[0].x(), -5.f);  // subject's right jaw at -x
  EXPECT_NEAR(lm[0].x(), -lm[16].x(), 1e-3f);
  EXPECT_GT(lm[19].y(), lm[8].y() + 8.f);  // +y up: brows over the chin (cm)
  EXPECT_GT(lm[30].z(), lm[0].z() + 5.f);  // the nose tip looks down +z
  // Triangles around the nose tip face +z (counter-clockwise seen from outside).
  const uint32_t tip = static_cast<uint32_t>(m.landmark_vertices()[30]);
  Vec3f normal = Vec3f::Zero();
  for (const auto& t : m.triangles())
    if (t[0] == tip || t[1] == tip || t[2] == tip) {
      const auto& p = m.neutral();
      normal += (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]);
    }
  EXPECT_GT(normal.normalized().z(), 0.9f);
  ASSERT_EQ(static_cast<int>(m.part_labels().size()), m.num_vertices());
  for (const char* part : {"face", "head_neck", "mouth_socket", "gums_tongue", "teeth", "sclera_left",
                           "iris_right", "eye_socket_left", "eyelashes_right"})
    EXPECT_GE(m.PartIndex(part), 0) << part;
  EXPECT_EQ(m.PartIndex("tail"), -1);
  const int face = m.PartIndex("face");
  for (int32_t v : m.landmark_vertices()) EXPECT_EQ(m.part_labels()[v], face);
  EXPECT_EQ(std::count(m.part_labels().begin(), m.part_labels().end(), m.PartIndex("teeth")), 4412);
  EXPECT_EQ(m.VertexSet("rigid_verts").size(), 1487u);
  EXPECT_EQ(m.VertexSet("jawline_left").size(), 8u);
  EXPECT_TRUE(m.VertexSet("no_such_set").empty());
}

TEST(IctModel, ParseArkitExpressionAcceptsBothSpellings) {
  ICT_MODEL_OR_SKIP(m);
  const auto w =
      Weights(m, "jawOpen=0.8, mouthSmileLeft=0.5,mouthSmile_R=0.25,browInnerUp=0.3,EyeBlinkRight=1");
  ASSERT_EQ(static_cast<int>(w.size()), m.num_expressions());
  const auto at = [&](const char* name) { return w[m.ExpressionIndex(name)]; };
  EXPECT_FLOAT_EQ(at("jawOpen"), 0.8f);
  EXPECT_FLOAT_EQ(at("mouthSmile_L"), 0.5f);
  EXPECT_FLOAT_EQ(at("mouthSmile_R"), 0.25f);
  EXPECT_FLOAT_EQ(at("browInnerUp_L"), 0.3f);
  EXPECT_FLOAT_EQ(at("browInnerUp_R"), 0.3f);
  EXPECT_FLOAT_EQ(at("eyeBlink_R"), 1.f);
  float sum = 0;
  for (float x : w) sum += x;
  EXPECT_FLOAT_EQ(sum, 0.8f + 0.5f + 0.25f + 0.6f + 1.f);
  const auto puff = Weights(m, "cheekPuff=1");
  EXPECT_EQ(puff[m.ExpressionIndex("cheekPuff_L")], 1.f);
  EXPECT_EQ(puff[m.ExpressionIndex("cheekPuff_R")], 1.f);
  EXPECT_EQ(Weights(m, "  "), std::vector<float>(m.num_expressions(), 0.f));
}

TEST(IctModel, ParseArkitExpressionRejectsWithOneLine) {
  ICT_MODEL_OR_SKIP(m);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"jawOpen=0.5,smile=1", "unknown expression 'smile'"},
      {"tongueOut=1", "tongueOut has no ICT blendshape"},
      {"jawOpen", "is not NAME=VALUE"},
      {"jawOpen=wide", "not a finite number"},
      {"jawOpen=nan", "not a finite number"},
      {"jawOpen=0.5,,mouthClose=1", "is not NAME=VALUE"},
      {"jawOpen=1,jawOpen=0.5", "already set"},
      {"browInnerUp=1,browInnerUp_L=0.5", "already set"}};
  for (const auto& [text, expected] : cases) {
    const auto r = ParseArkitExpression(m, text);
    ASSERT_FALSE(r.ok()) << text;
    const std::string msg = r.status().message();
    EXPECT_NE(msg.find(expected), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  const std::string msg = ParseArkitExpression(m, "smile=1").status().message();
  EXPECT_NE(msg.find("mouthSmile_L"), std::string::npos) << msg;  // lists the valid names
}

TEST(IctModel, BrokenFilesGiveOneLineErrorsNamingTheFile) {
  ICT_MODEL_OR_SKIP(m);
  const std::string bytes = ReadFile(m.path());
  ASSERT_GT(bytes.size(), 1000u);
  const fs::path dir = ScratchDir();
  std::string bad_magic = bytes.substr(0, 4096);
  bad_magic[0] = 'X';
  std::string bad_count = bytes;
  bad_count[8 + 6 * 4] = 5;  // num_landmarks = 5
  std::string bad_index = bytes;
  bad_index[96 + kVertices * 12 + 3] = '\x7f';  // first triangle index far out of range
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"truncated.bin", bytes.substr(0, bytes.size() / 2), "truncated"},
      {"header_only.bin", bytes.substr(0, 50), "truncated"},
      {"bad_magic.bin", bad_magic, "bad magic"},
      {"bad_count.bin", bad_count, "count of landmarks 5 is out of range"},
      {"bad_index.bin", bad_index, "triangles: index"},
      {"trailing.bin", bytes + "xx", "trailing data"}};
  for (const auto& [name, content, expected] : cases) {
    const fs::path path = WriteFile(dir / name, content);
    const auto r = IctModel::Load(path);
    ASSERT_FALSE(r.ok()) << name;
    const std::string msg = r.status().message();
    EXPECT_EQ(msg.rfind(path.string() + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find(expected), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  const auto missing = IctModel::Load(dir / "missing.bin");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("missing.bin: cannot open"), std::string::npos);
  fs::remove_all(dir);
}

TEST(IctModel, DefaultPathFollowsTheEnvironment) {
  const char* old = std::getenv("ICEF_FACE_MODEL");
  const std::string saved = old ? old : "";
  ::setenv("ICEF_FACE_MODEL", "/elsewhere/model.bin", 1);
  EXPECT_EQ(IctModel::DefaultPath(), fs::path("/elsewhere/model.bin"));
  ::unsetenv("ICEF_FACE_MODEL");
  EXPECT_EQ(IctModel::DefaultPath().filename(), "ict_facekit.bin");
  EXPECT_EQ(IctModel::DefaultPath().parent_path().filename(), "ict-facekit");
  if (old) ::setenv("ICEF_FACE_MODEL", saved.c_str(), 1);
}

}  // namespace
}  // namespace icef::face
