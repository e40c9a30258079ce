#include "icef/face/ict_warp.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <random>

namespace icef::face {
namespace {

// The model at DefaultPath(), loaded once; nullptr when the file is absent (tests skip).
const IctModel* Model() {
  static const Result<IctModel>* loaded = [] {
    const std::filesystem::path path = IctModel::DefaultPath();
    return std::filesystem::exists(path) ? new Result<IctModel>(IctModel::Load(path)) : nullptr;
  }();
  if (loaded == nullptr) return nullptr;
  EXPECT_TRUE(loaded->ok()) << loaded->status().message();
  return loaded->ok() ? &loaded->value() : nullptr;
}

// The warp of the mean identity with default options, built once.
const IctWarp* Warp() {
  static const IctWarp* warp = [] {
    const IctModel* model = Model();
    return model == nullptr ? nullptr : new IctWarp(IctWarp::Create(*model, {}).value());
  }();
  return warp;
}

#define ICT_WARP_OR_SKIP(w)                                                               \
  const IctWarp* w##_ptr = Warp();                                                        \
  if (w##_ptr == nullptr) GTEST_SKIP() << "no face model at " << IctModel::DefaultPath(); \
  const IctWarp& w = *w##_ptr

std::vector<float> Weights(const IctModel& m, std::string_view text) {
  auto w = ParseArkitExpression(m, text);
  EXPECT_TRUE(w.ok()) << w.status().message();
  return w.ok() ? *w : std::vector<float>(m.num_expressions(), 0.f);
}

// Distance from x to triangle (a, b, c), in double, by a method independent of the warp's: the
// plane's foot when it falls inside, else the nearest of the three edges.
double TriangleDistance(const Vec3d& x, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d n = (b - a).cross(c - a);
  const Vec3d foot = x - n * (n.dot(x - a) / n.squaredNorm());
  const double s0 = n.dot((b - foot).cross(c - foot)), s1 = n.dot((c - foot).cross(a - foot)),
               s2 = n.dot((a - foot).cross(b - foot));
  if (s0 >= 0 && s1 >= 0 && s2 >= 0) return (x - foot).norm();
  const auto segment = [&](const Vec3d& p, const Vec3d& q) {
    const double t = std::clamp((x - p).dot(q - p) / (q - p).squaredNorm(), 0.0, 1.0);
    return (x - (p + t * (q - p))).norm();
  };
  return std::min({segment(a, b), segment(b, c), segment(c, a)});
}

// The distance from x to the warp's surface on mesh, by brute force over all its triangles.
double BruteForceDistance(const IctWarp& warp, const std::vector<Vec3f>& mesh, const Vec3f& x) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : warp.triangles())
    best = std::min(best, TriangleDistance(x.cast<double>(), mesh[t[0]].cast<double>(),
                                           mesh[t[1]].cast<double>(), mesh[t[2]].cast<double>()));
  return best;
}

// count points x = (centroid of a random warp triangle of `part` on mesh) + distance * its normal.
std::vector<Vec3f> PointsOverTriangles(const IctWarp& warp, const std::vector<Vec3f>& mesh,
                                       std::string_view part, float distance, int count, uint32_t seed) {
  const int label = warp.model().PartIndex(part);
  std::vector<uint32_t> candidates;
  for (uint32_t t = 0; t < warp.triangles().size(); ++t)
    if (warp.model().part_labels()[warp.triangles()[t][0]] == label) candidates.push_back(t);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<size_t> pick(0, candidates.size() - 1);
  std::vector<Vec3f> points;
  for (int i = 0; i < count; ++i) {
    const auto& t = warp.triangles()[candidates[pick(rng)]];
    const Vec3f n = (mesh[t[1]] - mesh[t[0]]).cross(mesh[t[2]] - mesh[t[0]]).normalized();
    points.push_back((mesh[t[0]] + mesh[t[1]] + mesh[t[2]]) / 3.f + distance * n);
  }
  return points;
}

// count points uniform in the neutral head's box grown by margin cm.
std::vector<Vec3f> PointsInHeadBox(float margin, int count, uint32_t seed) {
  const Vec3f lo(-12.4f - margin, -19.3f - margin, -9.2f - margin),
      hi(12.4f + margin, 14.5f + margin, 13.1f + margin);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<Vec3f> points(count);
  for (Vec3f& p : points) p = lo + Vec3f(u(rng), u(rng), u(rng)).cwiseProduct(hi - lo);
  return points;
}

std::vector<Vec3f> Offsets(const PosedIctWarp& posed, const std::vector<Vec3f>& points, int threads = 2) {
  std::vector<Vec3f> offsets(points.size());
  posed.Offsets(Executor(threads), static_cast<int64_t>(points.size()), points.data()->data(),
                offsets.data()->data());
  return offsets;
}

TEST(IctWarpOptions, ValidateRejectsBadValues) {
  EXPECT_TRUE(IctWarpOptions{}.Validate().ok());
  const auto bad = [](auto edit) {
    IctWarpOptions o;
    edit(o);
    return !o.Validate().ok();
  };
  EXPECT_TRUE(bad([](IctWarpOptions& o) { o.inner_radius = -0.1f; }));
  EXPECT_TRUE(bad([](IctWarpOptions& o) { o.inner_radius = NAN; }));
  EXPECT_TRUE(bad([](IctWarpOptions& o) { o.outer_radius = o.inner_radius; }));
  EXPECT_TRUE(bad([](IctWarpOptions& o) { o.outer_radius = INFINITY; }));
  EXPECT_TRUE(bad([](IctWarpOptions& o) { o.tree_point_spacing = 0.f; }));
  EXPECT_TRUE(bad([](IctWarpOptions& o) { o.tree_point_spacing = NAN; }));
  EXPECT_FALSE(bad([](IctWarpOptions& o) { o.inner_radius = 0.f; }));
  EXPECT_EQ(IctWarpOptions{}.ToString(),
            "IctWarpOptions(inner_radius=1, outer_radius=3, tree_point_spacing=0.25)");
}

TEST(IctWarp, CreateRejectsBadOptionsAndIdentity) {
  const IctModel* m = Model();
  if (m == nullptr) GTEST_SKIP() << "no face model at " << IctModel::DefaultPath();
  IctWarpOptions o;
  o.outer_radius = 0.5f;
  const Result<IctWarp> bad_options = IctWarp::Create(*m, {}, o);
  ASSERT_FALSE(bad_options.ok());
  EXPECT_NE(bad_options.status().message().find("outer_radius"), std::string::npos);
  const std::vector<float> too_many(m->num_identities() + 1, 0.f);
  EXPECT_FALSE(IctWarp::Create(*m, too_many, {}).ok());
}

TEST(IctWarp, SurfaceIsTheVisibleMovingParts) {
  ICT_WARP_OR_SKIP(w);
  const IctModel& m = w.model();
  // Parts are vertex ranges and the surface parts' triangles are all of theirs (ict_model.h).
  size_t expected = 0;
  for (const auto& t : m.triangles()) {
    const std::string& part = m.part_names()[m.part_labels()[t[0]]];
    expected += part.starts_with("face") || part.starts_with("head_neck") || part.starts_with("mouth") ||
                part.starts_with("eye_socket") || part.starts_with("gums") || part.starts_with("teeth") ||
                part.starts_with("sclera") || part.starts_with("iris");
  }
  EXPECT_EQ(w.triangles().size(), expected);
  EXPECT_GT(w.triangles().size(), 45000u);
  EXPECT_EQ(w.neutral(), m.neutral());  // mean identity
  EXPECT_NE(w.ToString().find("triangles="), std::string::npos) << w.ToString();
}

TEST(IctWarp, IsTheIdentityAtRest) {
  ICT_WARP_OR_SKIP(w);
  std::vector<Vec3f> points = PointsInHeadBox(2.f, 3000, 1);
  for (const Vec3f& p : PointsOverTriangles(w, w.neutral(), "face", 0.5f, 2000, 2)) points.push_back(p);
  for (const Vec3f& p : PointsOverTriangles(w, w.neutral(), "teeth", -0.1f, 500, 3)) points.push_back(p);
  for (const std::vector<float>& rest : {std::vector<float>{}, std::vector<float>(53, 0.f)}) {
    const PosedIctWarp posed = w.Pose(rest);
    EXPECT_EQ(posed.posed(), w.neutral());
    float worst = 0;
    for (const Vec3f& o : Offsets(posed, points)) worst = std::max(worst, o.norm());
    EXPECT_EQ(worst, 0.f);
  }
}

// Posed vertices of the face part land on the neutral's vertices.
void ExpectVerticesMapToNeutral(const IctWarp& w, std::string_view expression) {
  const IctModel& m = w.model();
  const PosedIctWarp posed = w.Pose(Weights(m, expression));
  const int face = m.PartIndex("face");
  std::vector<int> vertices;
  for (int v = 0; v < m.num_vertices() && vertices.size() < 200; v += 47)
    if (m.part_labels()[v] == face) vertices.push_back(v);
  ASSERT_EQ(vertices.size(), 200u);
  std::vector<Vec3f> points;
  for (int v : vertices) points.push_back(posed.posed()[v]);
  const std::vector<Vec3f> offsets = Offsets(posed, points);
  float worst = 0, moved = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    worst = std::max(worst, (points[i] + offsets[i] - w.neutral()[vertices[i]]).norm());
    moved = std::max(moved, (points[i] - w.neutral()[vertices[i]]).norm());
  }
  EXPECT_LT(worst, 1e-3f) << expression;
  EXPECT_GT(moved, 0.5f) << expression;  // the test means something
}

TEST(IctWarp, PosedVerticesMapToTheNeutral) {
  ICT_WARP_OR_SKIP(w);
  ExpectVerticesMapToNeutral(w, "jawOpen=1");
  ExpectVerticesMapToNeutral(w, "mouthSmile_L=1");
  // The posed mesh is the model's mesh at that expression, the blinks left out (the lid slide's).
  const PosedIctWarp posed = w.Pose(Weights(w.model(), "jawOpen=1,eyeBlink_L=1"));
  const std::vector<Vec3f> mesh = w.model().Mesh({}, Weights(w.model(), "jawOpen=1"));
  for (size_t v = 0; v < mesh.size(); v += 101) EXPECT_LT((posed.posed()[v] - mesh[v]).norm(), 1e-5f);
}

TEST(IctWarp, MapsToTheNeutralOfItsIdentity) {
  const IctModel* m = Model();
  if (m == nullptr) GTEST_SKIP() << "no face model at " << IctModel::DefaultPath();
  const std::vector<float> identity = {1.f, -0.5f, 0.8f, 0.f, -1.2f};
  const IctWarp w = IctWarp::Create(*m, identity).value();
  EXPECT_EQ(w.neutral(), m->Mesh(identity, {}));
  const std::vector<float> beta = Weights(*m, "jawOpen=1,mouthFunnel=0.5");
  const PosedIctWarp posed = w.Pose(beta);
  const std::vector<Vec3f> mesh = m->Mesh(identity, beta);
  std::vector<Vec3f> points;
  std::vector<int> vertices;
  for (int v = 0; v < m->num_vertices() && vertices.size() < 200; v += 53) {
    if (m->part_labels()[v] != m->PartIndex("face")) continue;
    vertices.push_back(v);
    points.push_back(posed.posed()[v]);
    EXPECT_LT((posed.posed()[v] - mesh[v]).norm(), 1e-4f);
  }
  const std::vector<Vec3f> offsets = Offsets(posed, points);
  for (size_t i = 0; i < points.size(); ++i)
    EXPECT_LT((points[i] + offsets[i] - w.neutral()[vertices[i]]).norm(), 1e-3f) << vertices[i];
}

TEST(IctWarp, APointOutsideTheChinMapsOutsideTheNeutralChin) {
  ICT_WARP_OR_SKIP(w);
  const PosedIctWarp posed = w.Pose(Weights(w.model(), "jawOpen=1"));
  const int chin = w.model().landmark_vertices()[8];  // iBUG 8, the chin's tip
  const Vec3f normal = w.VertexNormals(posed.posed())[chin];
  const Vec3f canonical_normal = w.VertexNormals(w.neutral())[chin];
  const Vec3f x = posed.posed()[chin] + normal;
  const Vec3f mapped = x + Offsets(posed, {x})[0];
  const Vec3f from_chin = mapped - w.neutral()[chin];
  EXPECT_GT((posed.posed()[chin] - w.neutral()[chin]).norm(), 2.f);  // jawOpen moves the chin
  EXPECT_NEAR(from_chin.norm(), 1.f, 0.05f) << from_chin.transpose();
  EXPECT_GT(from_chin.dot(canonical_normal), 0.95f) << from_chin.transpose();
}

TEST(IctWarp, TheClosestPointIsExact) {
  ICT_WARP_OR_SKIP(w);
  const PosedIctWarp posed = w.Pose(Weights(w.model(), "jawOpen=1,mouthSmile_L=0.5,eyeBlink_R=1"));
  std::vector<Vec3f> points = PointsInHeadBox(1.f, 150, 4);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> distance(-2.9f, 2.9f);
  for (const char* part : {"face", "teeth", "gums_tongue", "mouth_socket", "head_neck", "sclera_right"})
    for (int i = 0; i < 40; ++i)
      points.push_back(PointsOverTriangles(w, posed.posed(), part, distance(rng), 1, rng())[0]);
  int near = 0;
  for (const Vec3f& x : points) {
    const double brute = BruteForceDistance(w, posed.posed(), x);
    const IctWarpClosest closest = posed.Closest(x);
    if (brute < w.options().outer_radius - 1e-3) {
      ++near;
      ASSERT_GE(closest.triangle, 0) << x.transpose();
      EXPECT_NEAR(closest.distance, brute, 1e-4) << x.transpose() << " " << closest.ToString();
      EXPECT_NEAR(closest.barycentric.sum(), 1.f, 1e-5f);
    } else if (brute > w.options().outer_radius + 1e-3) {
      EXPECT_EQ(closest.triangle, -1) << x.transpose();
      EXPECT_EQ(posed.Offset(x), Vec3f::Zero()) << x.transpose();  // beyond the outer radius
    }
  }
  EXPECT_GT(near, 240);
}

TEST(IctWarp, PointsBeyondTheOuterRadiusDoNotMove) {
  ICT_WARP_OR_SKIP(w);
  const PosedIctWarp posed = w.Pose(Weights(w.model(), "jawOpen=1"));
  // 3.2 cm out from face triangles; the brute-force distance keeps those whose surface is beyond 3 cm.
  std::vector<Vec3f> points = PointsOverTriangles(w, posed.posed(), "face", 3.2f, 300, 6);
  const std::vector<Vec3f> offsets = Offsets(posed, points);
  int beyond = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (BruteForceDistance(w, posed.posed(), points[i]) <= w.options().outer_radius) continue;
    ++beyond;
    EXPECT_EQ(offsets[i], Vec3f::Zero()) << points[i].transpose();
  }
  EXPECT_GT(beyond, 100);
}

TEST(IctWarp, FadesWithASmoothstepBetweenTheRadii) {
  ICT_WARP_OR_SKIP(w);
  IctWarpOptions full_options;  // weight 1 out to 2.9 cm
  full_options.inner_radius = 2.9f;
  const IctWarp full = IctWarp::Create(w.model(), {}, full_options).value();
  const std::vector<float> beta = Weights(w.model(), "jawOpen=1");
  const PosedIctWarp posed = w.Pose(beta), posed_full = full.Pose(beta);
  // Over the chin and lower lip, which jawOpen moves by centimetres.
  const int chin = w.model().landmark_vertices()[8];
  const Vec3f normal = w.VertexNormals(posed.posed())[chin];
  for (float distance : {0.5f, 2.f}) {
    const Vec3f x = posed.posed()[chin] + distance * normal;
    const float d = posed.Closest(x).distance;
    ASSERT_NEAR(d, distance, 0.05f);
    const float s = std::clamp((3.f - d) / 2.f, 0.f, 1.f);  // 1 up to 1 cm, 0 from 3 cm
    const float weight = s * s * (3.f - 2.f * s);
    const Vec3f expected = weight * posed_full.Offset(x);
    EXPECT_GT(expected.norm(), 1.f);
    EXPECT_LT((posed.Offset(x) - expected).norm(), 1e-2f * expected.norm()) << distance;
  }
}

TEST(IctWarp, IsContinuousNearTheSurface) {
  ICT_WARP_OR_SKIP(w);
  const PosedIctWarp posed = w.Pose(Weights(w.model(), "jawOpen=1,mouthSmile_L=1"));
  std::mt19937 rng(8);
  std::normal_distribution<float> gauss;
  float worst = 0;
  for (float distance : {0.1f, 0.5f, 2.f}) {
    const std::vector<Vec3f> points = PointsOverTriangles(w, posed.posed(), "face", distance, 500, 9);
    std::vector<Vec3f> stepped;
    for (const Vec3f& p : points)
      stepped.push_back(p + 1e-3f * Vec3f(gauss(rng), gauss(rng), gauss(rng)).normalized());
    const std::vector<Vec3f> a = Offsets(posed, points), b = Offsets(posed, stepped);
    float worst_here = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      const float jump = ((stepped[i] + b[i]) - (points[i] + a[i])).norm();
      worst_here = std::max(worst_here, jump);
    }
    std::printf("[ continuity ] %.1f cm over face triangles: a 1e-3 cm step moves P by at most %.2e cm\n",
                distance, worst_here);
    if (distance <= 0.5f) worst = std::max(worst, worst_here);
  }
  EXPECT_LT(worst, 0.05f);
}

// Pixels that show the left eyeball in an ideal render through the warp: the canonical scene is a
// 0.1-cm shell around the neutral surface (a point within 0.05 cm of it shows the part of its closest
// point there), and orthographic rays along -z (the face looks down +z) cross a 3.6 x 2.4 cm window
// around the eye in steps of 0.02 cm; a pixel shows the first sample whose canonical point lies in the
// shell. The eyeball is sclera (which includes the cornea) and iris.
int VisibleEyeballPixels(const IctWarp& w, const PosedIctWarp& posed) {
  const IctModel& m = w.model();
  const PosedIctWarp rest = w.Pose({});
  const std::vector<uint8_t>& labels = m.part_labels();
  const int iris = m.PartIndex("iris_left"), sclera = m.PartIndex("sclera_left");
  Vec3f centre = Vec3f::Zero();
  int count = 0;
  for (int v = 0; v < m.num_vertices(); ++v)
    if (labels[v] == iris) centre += w.neutral()[v], ++count;
  centre /= static_cast<float>(count);
  constexpr int kWidth = 45, kHeight = 30;
  constexpr float kPixel = 0.08f;
  int eyeball = 0;
  for (int j = 0; j < kHeight; ++j) {
    for (int i = 0; i < kWidth; ++i) {
      const float x = centre.x() + 0.3f + (i - kWidth / 2) * kPixel,
                  y = centre.y() - (j - kHeight / 2) * kPixel;
      for (float z = centre.z() + 2.f; z > centre.z() - 1.5f; z -= 0.02f) {
        const Vec3f p(x, y, z);
        const IctWarpClosest hit = rest.Closest(p + posed.Offset(p));
        if (hit.triangle < 0 || hit.distance > 0.05f) continue;
        const int part = labels[w.triangles()[hit.triangle][0]];
        eyeball += part == iris || part == sclera;
        break;
      }
    }
  }
  return eyeball;
}

// Closing the lid covers the eye: the space in front of the eyeball slides to the open lid's skin,
// whatever the identity. ICT's own eyeBlink delta, made on the mean face, left identities drawn from
// the model's N(0, 1) modes partly open (two of the three here kept 53 and 140 eyeball pixels at
// eyeBlink_L = 1).
TEST(IctWarp, AClosedLidHidesTheEyeOfAnyIdentity) {
  ICT_WARP_OR_SKIP(mean);
  std::vector<IctWarp> drawn;
  std::mt19937 rng(7);
  std::normal_distribution<float> normal;
  for (int i = 0; i < 3; ++i) {
    std::vector<float> identity(mean.model().num_identities());
    for (float& c : identity) c = normal(rng);
    drawn.push_back(IctWarp::Create(mean.model(), identity).value());
  }
  std::vector<const IctWarp*> warps = {&mean};
  for (const IctWarp& w : drawn) warps.push_back(&w);
  for (const IctWarp* w : warps) {
    const int open = VisibleEyeballPixels(*w, w->Pose({}));
    const int half = VisibleEyeballPixels(*w, w->Pose(Weights(w->model(), "eyeBlink_L=0.5")));
    const int closed = VisibleEyeballPixels(*w, w->Pose(Weights(w->model(), "eyeBlink_L=1")));
    const int over = VisibleEyeballPixels(*w, w->Pose(Weights(w->model(), "eyeBlink_L=1.5,jawOpen=0.5")));
    std::printf("[ lid ] eyeball pixels: open %d, eyeBlink_L=0.5 %d, eyeBlink_L=1 %d\n", open, half, closed);
    EXPECT_GT(open, 150);  // measured 240 on the mean (of 1350)
    EXPECT_LT(half, 0.7 * open);
    EXPECT_GT(half, 0.3 * open);
    // At most one grazing pixel at the eye's corner (measured 0 or 1; ICT's own blink: 53 and 140).
    EXPECT_LE(closed, open / 100);
    EXPECT_EQ(over, closed);  // weights above 1 act as 1
  }
}

// The lid slide's rest opening is where the lids are: the mean face's eyelid landmarks (iBUG 37, 38,
// 43, 44 on the upper lids, 40, 41, 46, 47 on the lower) lie at the opening's upper and lower
// elevation of their column (measured within 0.02 rad), and the two eyes mirror each other.
TEST(IctWarp, TheEyeOpeningIsBetweenTheLids) {
  ICT_WARP_OR_SKIP(w);
  const std::vector<Vec3f> landmarks = w.model().Landmarks(w.neutral());
  const int upper_lid[2][2] = {{43, 44}, {37, 38}}, lower_lid[2][2] = {{46, 47}, {40, 41}};
  for (int side = 0; side < 2; ++side) {
    const IctEye& eye = w.eyes()[side];
    EXPECT_EQ(eye.blink, w.model().ExpressionIndex(side == 0 ? "eyeBlink_L" : "eyeBlink_R"));
    EXPECT_GT(eye.radius, 1.f);
    for (int k = 0; k < 2; ++k) {
      for (const auto& [index, upper] : {std::pair{upper_lid[side][k], true}, {lower_lid[side][k], false}}) {
        const Vec3f q = landmarks[index] - eye.centre;
        const auto [lower_edge, upper_edge] = eye.Opening(q.x() / eye.radius);
        EXPECT_NEAR(std::atan2(q.y(), q.z()), upper ? upper_edge : lower_edge, 0.05f) << "landmark " << index;
      }
    }
    EXPECT_GT(*std::max_element(eye.upper.begin(), eye.upper.end()), 0.1f);
  }
  EXPECT_NEAR(w.eyes()[0].centre.x(), -w.eyes()[1].centre.x(), 1e-3f);
  for (int k = 0; k < IctEye::kColumns; ++k) {
    EXPECT_NEAR(w.eyes()[0].upper[k], w.eyes()[1].upper[IctEye::kColumns - 1 - k], 0.03f) << k;
    EXPECT_NEAR(w.eyes()[0].lower[k], w.eyes()[1].lower[IctEye::kColumns - 1 - k], 0.03f) << k;
  }
  // No blink, no slide; a blink slides only what lies over its own eyeball.
  const PosedIctWarp open = w.Pose(Weights(w.model(), "jawOpen=1"));
  const PosedIctWarp blink = w.Pose(Weights(w.model(), "eyeBlink_L=1"));
  std::vector<Vec3f> points = PointsInHeadBox(0.f, 10000, 21);
  std::mt19937 rng(22);
  std::uniform_real_distribution<float> around(-2.5f, 2.5f);
  for (int i = 0; i < 5000; ++i)
    points.push_back(w.eyes()[0].centre + Vec3f(around(rng), around(rng), around(rng)));
  int slid = 0;
  for (const Vec3f& x : points) {
    EXPECT_EQ(open.LidSlide(x), x);
    const Vec3f y = blink.LidSlide(x);
    const float from_eye = (x - w.eyes()[0].centre).norm() - w.eyes()[0].radius;
    if (from_eye > 0.9f || from_eye < -0.6f || x.z() < w.eyes()[0].centre.z())
      EXPECT_EQ(y, x);
    else
      slid += y != x;
  }
  EXPECT_GT(slid, 200);
}

TEST(IctWarp, GivesTheSameResultsForAnyThreadCount) {
  ICT_WARP_OR_SKIP(w);
  const PosedIctWarp posed = w.Pose(Weights(w.model(), "jawOpen=0.7,browInnerUp=0.4"));
  std::vector<Vec3f> points = PointsInHeadBox(1.f, 10000, 10);
  for (const Vec3f& p : PointsOverTriangles(w, posed.posed(), "face", 0.3f, 5000, 11)) points.push_back(p);
  const std::vector<Vec3f> one = Offsets(posed, points, 1), two = Offsets(posed, points, 2),
                           three = Offsets(posed, points, 3);
  EXPECT_EQ(one, two);
  EXPECT_EQ(one, three);
  EXPECT_NE(posed.ToString().find("jawOpen=0.7"), std::string::npos) << posed.ToString();
}

// Not an assertion: prints how long posing and warping take on this host (wall and process CPU time;
// a busy host inflates the wall time).
TEST(IctWarp, Timing) {
  ICT_WARP_OR_SKIP(w);
  using Clock = std::chrono::steady_clock;
  struct Stopwatch {
    Clock::time_point wall = Clock::now();
    std::clock_t cpu = std::clock();
    std::string Report() const {
      const double wall_ms = std::chrono::duration<double, std::milli>(Clock::now() - wall).count();
      const double cpu_ms = 1e3 * static_cast<double>(std::clock() - cpu) / CLOCKS_PER_SEC;
      char text[64];
      std::snprintf(text, sizeof(text), "%.1f ms wall, %.1f ms cpu", wall_ms, cpu_ms);
      return text;
    }
  };
  const std::vector<float> beta =
      Weights(w.model(), "jawOpen=0.6,mouthSmile_L=0.5,eyeBlink_R=0.8,browInnerUp=0.3");
  Stopwatch pose_watch;
  const PosedIctWarp posed = w.Pose(beta);
  std::printf("[ timing ] Pose: %s; %s\n", pose_watch.Report().c_str(), posed.ToString().c_str());
  const std::vector<Vec3f> box = PointsInHeadBox(2.f, 100000, 12);
  const std::vector<Vec3f> shell = PointsOverTriangles(w, posed.posed(), "face", 0.5f, 100000, 13);
  for (const auto& [name, points] :
       {std::pair{"uniform in the head box + 2 cm", &box}, {"0.5 cm over the face", &shell}}) {
    for (int threads : {1, 2}) {
      Stopwatch watch;
      const std::vector<Vec3f> offsets = Offsets(posed, *points, threads);
      std::printf("[ timing ] Offsets, 100k points %s, %d thread(s): %s\n", name, threads,
                  watch.Report().c_str());
    }
  }
}

}  // namespace
}  // namespace icef::face
