#include "icef/track/photo_track.h"

#include <gtest/gtest.h>
#include <libexif/exif-data.h>
#include <stb_image_write.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>

#include "icef/face/expression.h"
#include "icef/face/ict_model.h"
#include "icef/io/atomic_file.h"
#include "icef/synth/photo_set.h"

namespace icef::track {
namespace {

namespace fs = std::filesystem;

bool HavePredictor() { return fs::exists(kDefaultShapePredictorPath); }

struct Scratch {
  fs::path dir;
  Scratch() {
    dir = fs::temp_directory_path() / ("icef_track_test_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~Scratch() { fs::remove_all(dir); }
};

// Three synthetic photos of one subject, written as PNG files; the truth stays in memory.
struct Photos {
  std::vector<synth::SynthPhoto> truth;
  std::vector<fs::path> files;
};

Photos MakePhotos(const fs::path& dir, uint64_t seed) {
  synth::PhotoSetOptions o;
  o.identity_seed = seed;
  o.num_photos = 3;
  o.width = 300;
  o.height = 400;
  o.min_head_fraction = 0.45;
  o.max_head_fraction = 0.55;
  o.max_yaw_deg = 20;
  o.render.supersample = 1;
  Photos p;
  p.truth = *synth::RenderPhotoSet(o, Executor(2));
  for (size_t i = 0; i < p.truth.size(); ++i) {
    p.files.push_back(dir / ("photo_" + std::to_string(i) + ".png"));
    EXPECT_TRUE(WritePng(p.files.back(), p.truth[i].image).ok());
  }
  return p;
}

TrackOptions Options() {
  TrackOptions o;
  o.resolution = 128;
  o.focal = 1.4 * 400;  // the photo set's focal_scale x max(width, height)
  return o;
}

// The truth's coverage cropped like the dataset image (nearest pixel).
Image CropTruth(const Image& alpha, const CropBox& box, int res) {
  Image out(res, res, 1);
  for (int y = 0; y < res; ++y)
    for (int x = 0; x < res; ++x) {
      const int px = static_cast<int>(std::floor(box.x0 + (x + 0.5) * box.size / res));
      const int py = static_cast<int>(std::floor(box.y0 + (y + 0.5) * box.size / res));
      if (px >= 0 && py >= 0 && px < alpha.width && py < alpha.height) out.At(x, y, 0) = alpha.At(px, py, 0);
    }
  return out;
}

class PhotoTrackTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!HavePredictor()) GTEST_SKIP() << kDefaultShapePredictorPath << " not installed";
    detector_ = std::make_unique<FaceLandmarkDetector>(*FaceLandmarkDetector::Load());
  }
  std::unique_ptr<FaceLandmarkDetector> detector_;
  Scratch scratch_;
};

TEST_F(PhotoTrackTest, SyntheticPhotosBecomeADatasetInTheHeadFrame) {
  const Photos photos = MakePhotos(scratch_.dir, 2);
  TrackOptions options = Options();
  options.num_test = 1;
  const Result<TrackResult> result = TrackPhotos(photos.files, options, *detector_, Executor(2));
  ASSERT_TRUE(result.ok()) << result.status().message();
  const TrackResult& r = *result;
  ASSERT_EQ(r.photos.size(), 3u);
  EXPECT_EQ(r.dataset.train.size(), 2u);
  EXPECT_EQ(r.dataset.test.size(), 1u);
  EXPECT_EQ(r.dataset.expression_names, face::ExpressionNames());
  ASSERT_TRUE(r.dataset.test[0].tier.has_value());
  for (size_t i = 0; i < 3; ++i) {
    const TrackedPhoto& p = r.photos[i];
    const Frame& f = (p.test ? r.dataset.test : r.dataset.train)[p.frame_index];
    EXPECT_TRUE(ValidateRigid(f.camera.world_from_cam()).ok());
    EXPECT_EQ(f.camera.width(), 128);
    EXPECT_EQ(p.focal_source, FocalSource::kFlag);
    // Pose: the tracked camera-to-head rotation against the truth's (loose: dlib on a synthetic head).
    const Mat3d d = f.camera.world_from_cam().block<3, 3>(0, 0).transpose() *
                    photos.truth[i].camera.world_from_cam().block<3, 3>(0, 0);
    EXPECT_LT(Eigen::AngleAxisd(d).angle() * 180 / M_PI, 15.0) << "photo " << i;
    EXPECT_LT(r.fit.frames[i].rms_iod, 0.1) << "photo " << i;
    // The refit used the mask's edge between the chin and the brows.
    EXPECT_GT(r.fit.frames[i].silhouette_used, 10) << "photo " << i;
    EXPECT_LT(r.fit.frames[i].silhouette_rms_iod, 0.1) << "photo " << i;
    EXPECT_EQ(static_cast<int>(r.fit.frames[i].silhouette_points.size()), r.fit.frames[i].silhouette_used);
    // The photometric refit saw the face in every photo and its colours agree.
    EXPECT_GT(r.fit.frames[i].photometric_used, 100) << "photo " << i;
    EXPECT_LT(r.fit.frames[i].photometric_rms, 0.1) << "photo " << i;
    // The mask against the true coverage, cropped the same way.
    ASSERT_EQ(p.image.channels, 4);
    Image mask(128, 128, 1);
    for (int y = 0; y < 128; ++y)
      for (int x = 0; x < 128; ++x) mask.At(x, y, 0) = p.image.At(x, y, 3);
    EXPECT_GT(MaskIou(mask, CropTruth(photos.truth[i].alpha, p.crop, 128)), 0.85) << "photo " << i;
    // The crop's landmarks are the photo's, carried by the crop.
    const std::vector<Vec2f> crop = CropPoints(p.detection.landmarks, p.crop, 128);
    EXPECT_NEAR((*f.landmarks_2d)[30].x(), crop[30].x(), 1e-4);
  }

  // Written, it loads back as a dataset; the report names every photo.
  const fs::path out = scratch_.dir / "dataset";
  ASSERT_TRUE(WriteTrackedDataset(r, out).ok());
  const Result<Dataset> loaded = LoadDataset(out);
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_EQ(loaded->train.size(), 2u);
  EXPECT_TRUE(fs::exists(out / "track" / "report.json"));
  EXPECT_EQ(TrackReportJson(r)["photos"].size(), 3u);
  // Nothing is written over an existing dataset.
  EXPECT_NE(WriteTrackedDataset(r, out).message().find("already exists"), std::string::npos);

  // Deterministic.
  const Result<TrackResult> again = TrackPhotos(photos.files, options, *detector_, Executor(1));
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->photos[1].image.pixels, r.photos[1].image.pixels);
  EXPECT_EQ(again->fit.frames[1].expression, r.fit.frames[1].expression);
}

// --face-model ict: the same photos (of a procedural head: a model mismatch) as a dataset in
// ICT-FaceKit's 53 expressions, its world frame the scaled ICT head frame.
TEST_F(PhotoTrackTest, IctFaceModelWritesADatasetInItsExpressionSpace) {
  const Photos photos = MakePhotos(scratch_.dir, 2);
  TrackOptions options = Options();
  options.num_test = 1;
  options.face_model = TrackFaceModel::kIct;
  const Result<TrackResult> result = TrackPhotos(photos.files, options, *detector_, Executor(2));
  ASSERT_TRUE(result.ok()) << result.status().message();
  const TrackResult& r = *result;
  const face::IctModel& ict = **face::IctModel::LoadDefault();
  EXPECT_EQ(r.dataset.expression_names, ict.expression_names());
  EXPECT_EQ(r.dataset.expression_dim, 53);
  EXPECT_FALSE(r.fit.ict_identity.empty());
  for (size_t i = 0; i < 3; ++i) {
    const TrackedPhoto& p = r.photos[i];
    const Frame& f = (p.test ? r.dataset.test : r.dataset.train)[p.frame_index];
    EXPECT_TRUE(ValidateRigid(f.camera.world_from_cam()).ok());
    EXPECT_EQ(f.expression.size(), 53u);
    const Mat3d d = f.camera.world_from_cam().block<3, 3>(0, 0).transpose() *
                    photos.truth[i].camera.world_from_cam().block<3, 3>(0, 0);
    EXPECT_LT(Eigen::AngleAxisd(d).angle() * 180 / M_PI, 15.0) << "photo " << i;
    EXPECT_LT(r.fit.frames[i].rms_iod, 0.1) << "photo " << i;
    // The model's landmarks (world frame), seen by the frame's camera, on the detected ones.
    const std::vector<Vec2f>& lm = *f.landmarks_2d;
    const float iod = ((lm[36] + lm[39]) * 0.5f - (lm[42] + lm[45]) * 0.5f).norm();
    double sum2 = 0;
    for (int j = 17; j < 68; ++j) {
      const auto uv = f.camera.Project((*f.landmarks_3d)[j].cast<double>());
      ASSERT_TRUE(uv.has_value());
      sum2 += (uv->uv.cast<float>() - lm[j]).squaredNorm();
    }
    EXPECT_LT(std::sqrt(sum2 / 51) / iod, 0.1) << "photo " << i;
    // Inside the dataset's box; the mask (GrabCut seeded by ICT's silhouette) on the true coverage.
    for (const Vec3f& x : *f.landmarks_3d) EXPECT_TRUE(r.dataset.aabb.Contains(x));
    Image mask(128, 128, 1);
    for (int y = 0; y < 128; ++y)
      for (int x = 0; x < 128; ++x) mask.At(x, y, 0) = p.image.At(x, y, 3);
    EXPECT_GT(MaskIou(mask, CropTruth(photos.truth[i].alpha, p.crop, 128)), 0.8) << "photo " << i;
  }
  const Json report = TrackReportJson(r);
  EXPECT_EQ(report["face_model"], "ict");
  EXPECT_TRUE(report["photos"][0]["expression"].contains("jawOpen"));
  const fs::path out = scratch_.dir / "ict_dataset";
  ASSERT_TRUE(WriteTrackedDataset(r, out).ok());
  const Result<Dataset> loaded = LoadDataset(out);
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_EQ(loaded->expression_names, ict.expression_names());
}

// The default detector is the face mesh (its 68 points read off MediaPipe's mesh); dlib's own
// landmarks remain a choice, fitted with their own offsets and noise.
TEST_F(PhotoTrackTest, EitherDetectorTracks) {
  const Photos photos = MakePhotos(scratch_.dir, 2);
  EXPECT_EQ(TrackFitOptions().detector, LandmarkDetector::kMesh);
  std::vector<std::vector<Vec2f>> landmarks;
  for (LandmarkDetector detector : {LandmarkDetector::kMesh, LandmarkDetector::kDlib}) {
    TrackOptions options = Options();
    options.fit.detector = detector;
    const Result<TrackResult> r = TrackPhotos(photos.files, options, *detector_, Executor(2));
    ASSERT_TRUE(r.ok()) << r.status().message();
    for (size_t i = 0; i < 3; ++i) {
      const Frame& f = r->dataset.train[r->photos[i].frame_index];
      const Mat3d d = f.camera.world_from_cam().block<3, 3>(0, 0).transpose() *
                      photos.truth[i].camera.world_from_cam().block<3, 3>(0, 0);
      EXPECT_LT(Eigen::AngleAxisd(d).angle() * 180 / M_PI, 10.0)
          << LandmarkDetectorName(detector) << " photo " << i;
      EXPECT_LT(r->fit.frames[i].rms_iod, 0.1) << LandmarkDetectorName(detector) << " photo " << i;
    }
    landmarks.push_back(r->photos[0].detection.landmarks);
  }
  // Two detectors, two sets of landmarks: the same face (within a tenth of the inter-ocular
  // distance, about 6 px here, at the eye corners) but not the same points.
  ASSERT_EQ(landmarks[0].size(), 68u);
  double differ = 0;
  for (int i = 0; i < 68; ++i) differ = std::max(differ, double((landmarks[0][i] - landmarks[1][i]).norm()));
  EXPECT_GT(differ, 0.5);
  for (int i : {36, 39, 42, 45})
    EXPECT_LT((landmarks[0][i] - landmarks[1][i]).norm(), 8.0) << "landmark " << i;
  EXPECT_NE(DetectorLandmarkOffsets(LandmarkDetector::kMesh, Vec3f(0, 0, 3))[48],
            DetectorLandmarkOffsets(LandmarkDetector::kDlib, Vec3f(0, 0, 3))[48]);
}

TEST_F(PhotoTrackTest, BadPhotosAreClearErrorsAndNothingIsWritten) {
  const Photos photos = MakePhotos(scratch_.dir, 3);
  // An unreadable file, named.
  const fs::path broken = scratch_.dir / "broken.jpg";
  std::ofstream(broken) << "not a jpeg";
  std::vector<fs::path> files = photos.files;
  files.push_back(broken);
  Result<TrackResult> r = TrackPhotos(files, Options(), *detector_, Executor(2));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("broken.jpg"), std::string::npos) << r.status().message();

  // A photo without a face: an error naming it, or skipped with skip_bad.
  const fs::path empty = scratch_.dir / "wall.png";
  ASSERT_TRUE(WritePng(empty, synth::PhotoBackground(5, 0, 300, 400)).ok());
  files = photos.files;
  files.push_back(empty);
  r = TrackPhotos(files, Options(), *detector_, Executor(2));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("wall.png: no face found"), std::string::npos) << r.status().message();
  TrackOptions skip = Options();
  skip.skip_bad = true;
  r = TrackPhotos(files, skip, *detector_, Executor(2));
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->photos.size(), 3u);
  ASSERT_EQ(r->skipped.size(), 1u);

  // Two faces in one photo.
  Image two(600, 400, 3);
  for (int y = 0; y < 400; ++y)
    for (int x = 0; x < 600; ++x)
      for (int c = 0; c < 3; ++c) two.At(x, y, c) = photos.truth[x < 300 ? 0 : 1].image.At(x % 300, y, c);
  const fs::path pair = scratch_.dir / "pair.png";
  ASSERT_TRUE(WritePng(pair, two).ok());
  r = TrackPhotos({photos.files[0], pair}, Options(), *detector_, Executor(2));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("pair.png: 2 faces found"), std::string::npos) << r.status().message();

  // No training photo left.
  TrackOptions all_test = Options();
  all_test.num_test = 1;
  r = TrackPhotos({photos.files[0]}, all_test, *detector_, Executor(2));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("at least one training photo"), std::string::npos);
}

TEST(HeadMaskTest, EdgePointsLieBetweenInsideAndOutsidePixels) {
  Image mask(10, 8, 1), outside(10, 8, 1);
  for (int y = 2; y < 6; ++y)
    for (int x = 3; x < 7; ++x)
      mask.At(x, y, 0) = 1.f;  // pixels [3, 7) x [2, 6): edges at x = 3, 7 and y = 2, 6
  std::vector<Vec2f> points = MaskEdgePoints(mask, Image(), 0);
  ASSERT_EQ(points.size(), 16u);
  for (const Vec2f& p : points) {
    const bool vertical = p.x() == 3.f || p.x() == 7.f, horizontal = p.y() == 2.f || p.y() == 6.f;
    EXPECT_TRUE(vertical != horizontal) << p.transpose();
  }
  // Edges touching pixels outside the photo are left out; max_points keeps an even subset.
  for (int y = 0; y < 8; ++y) outside.At(7, y, 0) = 1.f;
  points = MaskEdgePoints(mask, outside, 0);
  EXPECT_EQ(points.size(), 12u);
  for (const Vec2f& p : points) EXPECT_NE(p.x(), 7.f);
  EXPECT_EQ(MaskEdgePoints(mask, outside, 5).size(), 5u);
  // A mask reaching the image border has no edge there.
  Image full(6, 6, 1);
  for (float& v : full.pixels) v = 1.f;
  EXPECT_TRUE(MaskEdgePoints(full, Image(), 0).empty());
}

TEST(HeadMaskTest, SkinEdgesKeepTheFaceOutlineNotHair) {
  // A shaded skin disk (the face, radius 24 about (48, 48)) over a blue-grey background, with brown
  // "hair" covering its left side out to radius 32; the mask is face and hair.
  Image image(96, 96, 3), mask(96, 96, 1);
  for (int y = 0; y < 96; ++y)
    for (int x = 0; x < 96; ++x) {
      const float dx = x + 0.5f - 48.f, dy = y + 0.5f - 48.f, r = std::sqrt(dx * dx + dy * dy);
      Vec3f c(0.45f, 0.5f, 0.6f);
      if (r < 24.f) c = Vec3f(0.82f, 0.62f, 0.5f) * (1.f - 0.25f * r / 24.f);  // darker towards the outline
      if (dx < -12.f && r < 32.f && r >= 20.f) c = Vec3f(0.35f, 0.24f, 0.14f);
      for (int ch = 0; ch < 3; ++ch) image.At(x, y, ch) = c[ch];
      mask.At(x, y, 0) = (r < 24.f || (dx < -12.f && r < 32.f)) ? 1.f : 0.f;
    }
  // Landmarks: the eyes 20 px apart, everything else at the centre.
  std::vector<Vec2f> lm(68, Vec2f(48.f, 50.f));
  for (int i : {36, 39}) lm[i] = Vec2f(38.f, 44.f);
  for (int i : {42, 45}) lm[i] = Vec2f(58.f, 44.f);
  const SkinModel skin = FitSkinModel(image, lm);
  ASSERT_TRUE(skin.valid);
  EXPECT_LT(skin.Distance(Vec3f(0.82f, 0.62f, 0.5f) * 0.9f), 3.0);
  EXPECT_GT(skin.Distance(Vec3f(0.35f, 0.24f, 0.14f)), 3.0);
  const std::vector<Vec2f> points = MaskEdgePoints(mask, Image(), 0);
  const std::vector<bool> keep = SkinEdges(image, mask, points, skin, 0.08 * 20);
  ASSERT_EQ(keep.size(), points.size());
  int face = 0, hair = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const float dx = points[i].x() - 48.f;
    if (dx > 4.f) {  // the face's own outline against the background
      EXPECT_TRUE(keep[i]) << points[i].transpose();
      ++face;
    } else if (dx < -16.f) {  // the hair's outline
      EXPECT_FALSE(keep[i]) << points[i].transpose();
      ++hair;
    }
  }
  EXPECT_GT(face, 20);
  EXPECT_GT(hair, 20);
  // Landmarks off the image: no skin model, every point kept.
  const SkinModel none = FitSkinModel(image, std::vector<Vec2f>(68, Vec2f(-500.f, -500.f)));
  EXPECT_FALSE(none.valid);
  for (bool k : SkinEdges(image, mask, points, none, 2.0)) EXPECT_TRUE(k);
}

TEST(HeadMaskTest, HairAsDarkAsTheBackgroundStaysWhereTheSegmentationSeesThePerson) {
  // A skin-coloured disk (the face: the silhouette) under a cap of dark brown hair (radius 20,
  // above the disk) before a dark blue background: GrabCut's colour models, seeded with skin alone,
  // cut the hair off flat along the silhouette; the person segmentation, which sees disk and hair,
  // keeps it.
  Image image(64, 64, 3), silhouette(64, 64, 1), person(64, 64, 1);
  const auto in_disk = [](int x, int y, float r) {
    const float dx = x + 0.5f - 32.f, dy = y + 0.5f - 36.f;
    return dx * dx + dy * dy < r * r;
  };
  const auto in_hair = [&](int x, int y) { return in_disk(x, y, 20.f) && !in_disk(x, y, 14.f) && y < 34; };
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const Vec3f c = (in_disk(x, y, 14.f) ? Vec3f(0.85f, 0.62f, 0.5f)
                       : in_hair(x, y)     ? Vec3f(0.22f, 0.14f, 0.1f)
                                           : Vec3f(0.1f, 0.1f, 0.25f)) +
                      Vec3f::Constant(0.02f * ((x * 7 + y * 13) % 3 - 1));
      for (int ch = 0; ch < 3; ++ch) image.At(x, y, ch) = c[ch];
      silhouette.At(x, y, 0) = in_disk(x, y, 13.f) ? 1.f : 0.f;
      person.At(x, y, 0) = in_disk(x, y, 14.5f) || in_hair(x, y) ? 0.95f : 0.01f;
    }
  int hair = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) hair += in_hair(x, y);
  const auto kept = [&](const Image& mask) {
    int n = 0;
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x) n += mask.At(x, y, 0) > 0.5f && in_hair(x, y);
    return n;
  };
  EXPECT_LT(kept(HeadMask(image, silhouette, Image())), 0.2 * hair);          // cut off flat
  EXPECT_GT(kept(HeadMask(image, silhouette, Image(), person)), 0.8 * hair);  // kept
}

TEST(HeadMaskTest, PersonSegmentationBackgroundIsSureBackground) {
  // A skin-coloured disk (radius 14 about (32, 32)) on a blue background, and touching it on the
  // right a skin-coloured bar (a door frame beside the head): GrabCut's colour models alone keep
  // the bar with the head. The silhouette is the disk, a little smaller.
  Image image(64, 64, 3), silhouette(64, 64, 1), person(64, 64, 1), nobody(64, 64, 1);
  const auto in_disk = [](int x, int y, float r) {
    const float dx = x + 0.5f - 32.f, dy = y + 0.5f - 32.f;
    return dx * dx + dy * dy < r * r;
  };
  const auto in_bar = [](int x, int y) { return x >= 44 && x < 52 && y >= 14 && y < 50; };
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const bool skin = in_disk(x, y, 14.f) || in_bar(x, y);
      const Vec3f c = (skin ? Vec3f(0.85f, 0.62f, 0.5f) : Vec3f(0.2f, 0.3f, 0.7f)) +
                      Vec3f::Constant(0.02f * ((x * 7 + y * 13) % 3 - 1));
      for (int ch = 0; ch < 3; ++ch) image.At(x, y, ch) = c[ch];
      silhouette.At(x, y, 0) = in_disk(x, y, 13.f) ? 1.f : 0.f;
      person.At(x, y, 0) = in_disk(x, y, 15.f) ? 0.97f : 0.01f;  // the network sees the head only
    }
  const auto count = [&](const Image& mask, bool bar) {
    int n = 0;
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x)
        n += mask.At(x, y, 0) > 0.5f && (bar ? in_bar(x, y) && !in_disk(x, y, 15.f) : in_disk(x, y, 14.f));
    return n;
  };
  int disk = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) disk += in_disk(x, y, 14.f);
  const Image alone = HeadMask(image, silhouette, Image());
  EXPECT_GT(count(alone, true), 60);  // GrabCut alone keeps the bar within its probable band (99 pixels)
  const Image segmented = HeadMask(image, silhouette, Image(), person);
  EXPECT_EQ(count(segmented, true), 0);             // the segmentation's background is gone
  EXPECT_GT(count(segmented, false), 0.95 * disk);  // the head stays
  // A segmentation that sees nobody cannot remove the silhouette's sure core.
  const Image blind = HeadMask(image, silhouette, Image(), nobody);
  EXPECT_EQ(blind.At(32, 32, 0), 1.f);
  // The person alone: the segmentation's disk, less what lies outside the photo (the left half).
  Image outside(64, 64, 1);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 32; ++x) outside.At(x, y, 0) = 1.f;
  const Image alone_person = PersonMask(person, outside);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      EXPECT_EQ(alone_person.At(x, y, 0), in_disk(x, y, 15.f) && x >= 32 ? 1.f : 0.f) << x << "," << y;
  HeadMaskOptions bad;
  bad.person_background = 1.5;
  EXPECT_FALSE(bad.Validate().ok());
}

TEST(HeadMaskTest, BackgroundDifferenceMaskIsWhatStandsInFrontOfTheBackground) {
  // A striped background; the frame shows it with a disk (radius 12 about (32, 30)) in front, a
  // background-coloured hole in the disk, a lone changed pixel and a second, smaller blob.
  Image background(64, 48, 3), frame(64, 48, 4);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      const Vec3f bg = (x / 4) % 2 ? Vec3f(0.2f, 0.6f, 0.3f) : Vec3f(0.7f, 0.3f, 0.5f);
      const float dx = x + 0.5f - 32.f, dy = y + 0.5f - 30.f;
      const bool disk = dx * dx + dy * dy < 144.f, hole = std::abs(dx) < 2.f && std::abs(dy) < 2.f;
      const bool blob = x >= 55 && x < 59 && y >= 4 && y < 8;
      Vec3f c = bg;
      if ((disk && !hole) || blob) c = Vec3f(0.85f, 0.65f, 0.5f);
      if (x == 5 && y == 40) c = Vec3f(1.f, 1.f, 1.f);
      c += Vec3f::Constant(0.03f * ((x * 7 + y * 13) % 3 - 1));  // noise below the threshold
      for (int ch = 0; ch < 3; ++ch) background.At(x, y, ch) = bg[ch], frame.At(x, y, ch) = c[ch];
      frame.At(x, y, 3) = 1.f;  // alpha is ignored
    }
  const Image mask = BackgroundDifferenceMask(frame, background);
  ASSERT_EQ(mask.width, 64);
  ASSERT_EQ(mask.height, 48);
  int wrong = 0, inside = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      const float dx = x + 0.5f - 32.f, dy = y + 0.5f - 30.f;
      const bool disk = dx * dx + dy * dy < 144.f;  // the hole filled
      inside += disk;
      wrong += (mask.At(x, y, 0) > 0.5f) != disk;
    }
  EXPECT_LT(wrong, 0.05 * inside);          // the disk, with its hole filled
  EXPECT_EQ(mask.At(32, 30, 0), 1.f);       // the hole
  EXPECT_EQ(mask.At(5, 40, 0), 0.f);        // the lone pixel
  EXPECT_EQ(mask.At(56, 5, 0), 0.f);        // the smaller blob: only the largest component stays
  EXPECT_EQ(mask.At(32, 30 - 15, 0), 0.f);  // background outside the disk
  // Nothing in front: an empty mask.
  const Image none = BackgroundDifferenceMask(background, background);
  for (float v : none.pixels) EXPECT_EQ(v, 0.f);
}

TEST(PhotoCropTest, CropCarriesTheCameraAndThePoints) {
  Intrinsics k;
  k.width = 640;
  k.height = 480;
  k.fl_x = k.fl_y = 700;
  k.cx = 320;
  k.cy = 240;
  Mat4d pose = Mat4d::Identity();
  pose.block<3, 1>(0, 3) = Vec3d(0.1, 0.0, 3.0);
  const Camera photo(k, pose);
  const CropBox box = HeadCropBox(photo);
  EXPECT_GT(box.size, 100);
  const Camera crop(CropIntrinsics(k, box, 200), pose);
  for (const Vec3d& p : {Vec3d(0, 0, 0), Vec3d(0.2, -0.3, 0.1), Vec3d(-0.25, 0.35, -0.2)}) {
    const Vec2f in_photo = photo.Project(p)->uv.cast<float>();
    const std::vector<Vec2f> carried = CropPoints(std::vector<Vec2f>{in_photo}, box, 200);
    EXPECT_LT((carried[0].cast<double>() - crop.Project(p)->uv).norm(), 1e-3);
  }
  // The pixels follow: a bright dot in the photo lands where its point lands in the crop.
  Image image(640, 480, 3, 0.f);
  const Vec2d dot = photo.Project(Vec3d(0.1, 0.1, 0))->uv;
  for (int y = -2; y <= 2; ++y)
    for (int x = -2; x <= 2; ++x)
      for (int c = 0; c < 3; ++c)
        image.At(static_cast<int>(dot.x()) + x, static_cast<int>(dot.y()) + y, c) = 1.f;
  Image outside;
  const Image cropped = CropImage(image, box, 200, &outside);
  const Vec2d where = crop.Project(Vec3d(0.1, 0.1, 0))->uv;
  EXPECT_GT(cropped.At(static_cast<int>(where.x()), static_cast<int>(where.y()), 0), 0.5f);
  EXPECT_EQ(outside.width, 200);
}

TEST(PhotoCropTest, ExifAndDefaultFocalLengths) {
  EXPECT_NEAR(DefaultFocalPixels(640, 480), 35.0 / 43.2666 * 800, 1e-6);
  // A PNG has no EXIF.
  Scratch s;
  const fs::path png = s.dir / "x.png";
  ASSERT_TRUE(WritePng(png, Image(8, 8, 3)).ok());
  EXPECT_FALSE(ExifFocalPixels(png, 8, 8).has_value());
  EXPECT_FALSE(ExifFocalPixels(s.dir / "missing.jpg", 8, 8).has_value());
}

// A JPEG whose EXIF says FocalLengthIn35mmFilm = `mm` (libexif builds the APP1 segment, which goes
// right after the JPEG's start-of-image marker).
void WriteJpegWithExif(const fs::path& path, int width, int height, int mm, int orientation = 0) {
  std::string jpeg;
  std::vector<uint8_t> rgb(size_t(width) * height * 3, 128);
  stbi_write_jpg_to_func(
      [](void* ctx, void* data, int size) {
        static_cast<std::string*>(ctx)->append(static_cast<char*>(data), size);
      },
      &jpeg, width, height, 3, rgb.data(), 90);
  ExifData* exif = exif_data_new();
  exif_data_set_byte_order(exif, EXIF_BYTE_ORDER_INTEL);
  ExifEntry* entry = exif_entry_new();
  exif_content_add_entry(exif->ifd[EXIF_IFD_EXIF], entry);
  exif_entry_initialize(entry, EXIF_TAG_FOCAL_LENGTH_IN_35MM_FILM);
  exif_set_short(entry->data, EXIF_BYTE_ORDER_INTEL, static_cast<ExifShort>(mm));
  exif_entry_unref(entry);
  if (orientation > 0) {
    ExifEntry* o = exif_entry_new();
    exif_content_add_entry(exif->ifd[EXIF_IFD_0], o);
    exif_entry_initialize(o, EXIF_TAG_ORIENTATION);
    exif_set_short(o->data, EXIF_BYTE_ORDER_INTEL, static_cast<ExifShort>(orientation));
    exif_entry_unref(o);
  }
  unsigned char* data = nullptr;
  unsigned int size = 0;
  exif_data_save_data(exif, &data, &size);
  exif_data_unref(exif);
  std::string app1 = "\xFF\xE1";
  app1 += static_cast<char>((size + 2) >> 8);
  app1 += static_cast<char>((size + 2) & 0xFF);
  app1.append(reinterpret_cast<char*>(data), size);
  free(data);
  jpeg.insert(2, app1);
  std::ofstream(path, std::ios::binary) << jpeg;
}

TEST(PhotoCropTest, ExifFocalLengthIsReadFromAJpeg) {
  Scratch s;
  const fs::path jpg = s.dir / "exif.jpg";
  WriteJpegWithExif(jpg, 64, 48, 28);
  ASSERT_TRUE(ReadImage(jpg).ok());
  const auto focal = ExifFocalPixels(jpg, 640, 480);
  ASSERT_TRUE(focal.has_value());
  EXPECT_NEAR(*focal, 28.0 / 43.2666 * 800, 0.01);
}

TEST(PhotoCropTest, ExifOrientationTurnsThePhotoUpright) {
  Scratch s;
  const fs::path jpg = s.dir / "turned.jpg";
  WriteJpegWithExif(jpg, 64, 48, 28, 6);
  EXPECT_EQ(ExifOrientation(jpg), 6);
  EXPECT_EQ(ExifOrientation(s.dir / "missing.jpg"), 1);
  // A stored image with a marked top-left pixel, shown for each orientation.
  Image stored(4, 3, 1);
  stored.At(0, 0, 0) = 1.f;
  auto marked = [](const Image& im) {
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x)
        if (im.At(x, y, 0) > 0.5f) return Vec2i(x, y);
    return Vec2i(-1, -1);
  };
  EXPECT_EQ(marked(Oriented(stored, 1)), Vec2i(0, 0));
  EXPECT_EQ(marked(Oriented(stored, 2)), Vec2i(3, 0));
  EXPECT_EQ(marked(Oriented(stored, 3)), Vec2i(3, 2));
  EXPECT_EQ(marked(Oriented(stored, 4)), Vec2i(0, 2));
  const Image cw = Oriented(stored, 6);  // shown turned 90 degrees clockwise
  EXPECT_EQ(cw.width, 3);
  EXPECT_EQ(cw.height, 4);
  EXPECT_EQ(marked(cw), Vec2i(2, 0));
  EXPECT_EQ(marked(Oriented(stored, 8)), Vec2i(0, 3));
  EXPECT_EQ(marked(Oriented(stored, 5)), Vec2i(0, 0));
  EXPECT_EQ(marked(Oriented(stored, 7)), Vec2i(2, 3));
}

TEST(PhotoTrackArgs, DirectoriesExpandToTheirPhotosAndMissingPathsAreErrors) {
  Scratch s;
  for (const char* name : {"b.JPG", "a.png", "notes.txt"}) std::ofstream(s.dir / name) << "x";
  const auto files = ExpandPhotoArguments({s.dir});
  ASSERT_TRUE(files.ok());
  ASSERT_EQ(files->size(), 2u);
  EXPECT_EQ((*files)[0].filename(), "a.png");
  EXPECT_NE(ExpandPhotoArguments({s.dir / "nope.jpg"}).status().message().find("no such file"),
            std::string::npos);
}

}  // namespace
}  // namespace icef::track
