#include "icef/track/dataset_retrack.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "icef/face/expression.h"
#include "icef/face/ict_model.h"
#include "icef/io/image.h"
#include "icef/landmarks/face_landmark_detector.h"
#include "icef/synth/synthesize.h"

namespace icef::track {
namespace {

namespace fs = std::filesystem;

TEST(DatasetRetrackTest, FallsBackToTheDatasetsLandmarksWhereNoFaceIsFound) {
  if (!fs::exists(kDefaultShapePredictorPath)) GTEST_SKIP() << kDefaultShapePredictorPath << " not installed";
  const fs::path dir = fs::temp_directory_path() / ("icef_retrack_fallback_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  synth::SynthOptions so;
  so.out_dir = dir / "src";
  so.identity_seed = 5;
  so.num_train = 3;
  so.resolution = 192;
  so.test_views = 1;
  so.novel_per_tier = 1;
  so.render.supersample = 1;
  ASSERT_TRUE(synth::SynthesizeDataset(so, Executor(2)).ok());
  Result<Dataset> source = LoadDataset(so.out_dir);
  ASSERT_TRUE(source.ok()) << source.status().message();
  ASSERT_TRUE(source->train[1].landmarks_2d.has_value());
  // No face for the detector in training frame 1: a flat grey image.
  ASSERT_TRUE(WritePng(so.out_dir / source->train[1].file_path, Image(192, 192, 3, 0.5f)).ok());
  RetrackOptions o;
  o.fit.photometric_weight = 0;
  o.silhouette_points = 0;
  std::vector<std::string> lines;
  const Result<RetrackResult> r =
      RetrackDataset(*source, o, Executor(2), [&](const std::string& line) { lines.push_back(line); });
  ASSERT_TRUE(r.ok()) << r.status().message();
  ASSERT_EQ(r->fallbacks.size(), 1u);
  EXPECT_NE(r->fallbacks[0].find("train[1]"), std::string::npos) << r->fallbacks[0];
  EXPECT_TRUE(std::any_of(lines.begin(), lines.end(), [](const std::string& l) {
    return l.find("no face found; fitting the dataset's own landmarks_2d") != std::string::npos;
  }));
  EXPECT_EQ(r->dataset.train.size(), 3u);
  EXPECT_EQ(*r->dataset.train[1].landmarks_2d, *source->train[1].landmarks_2d);
  fs::remove_all(dir);
}

TEST(DatasetRetrackTest, SyntheticDatasetKeepsItsCamerasAndGetsItsExpressionsBack) {
  if (!fs::exists(kDefaultShapePredictorPath)) GTEST_SKIP() << kDefaultShapePredictorPath << " not installed";
  const fs::path dir = fs::temp_directory_path() / ("icef_retrack_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  synth::SynthOptions so;
  so.out_dir = dir / "src";
  so.identity_seed = 4;
  so.num_train = 4;
  so.resolution = 192;
  so.test_views = 1;
  so.novel_per_tier = 1;
  so.render.supersample = 1;
  ASSERT_TRUE(synth::SynthesizeDataset(so, Executor(2)).ok());
  const Result<Dataset> source = LoadDataset(so.out_dir);
  ASSERT_TRUE(source.ok()) << source.status().message();

  const Result<RetrackResult> r = RetrackDataset(*source, {}, Executor(2));
  ASSERT_TRUE(r.ok()) << r.status().message();
  const Dataset& d = r->dataset;
  EXPECT_EQ(d.expression_names, face::ExpressionNames());
  ASSERT_EQ(d.train.size(), source->train.size());
  ASSERT_EQ(d.test.size(), source->test.size());
  // The synthetic world frame is the head frame: the similarity is close to the identity.
  const face::Similarity& s = *r->fit.head_from_world;
  EXPECT_NEAR(s.scale, 1.0, 0.1) << s.ToString();
  // The face mesh's landmarks (the default) with the outlines: 2.2 degrees on this head.
  const double rotation_deg = Eigen::AngleAxisd(s.rotation).angle() * 180 / M_PI;
  EXPECT_LT(rotation_deg, 4.0) << s.ToString();
  for (const TrackedFrame& f : r->fit.frames) EXPECT_GT(f.silhouette_used, 10) << f.ToString();
  // The outlines placed the similarity: the refit holds it (the same as without the refit, below)
  // and reads the expressions at its higher weight.
  EXPECT_EQ(r->outlined_frames, static_cast<int>(r->fit.frames.size()));
  EXPECT_TRUE(r->similarity_held);
  EXPECT_EQ(r->photometric_weight, kRetrackPhotometricWeightWithOutlines);
  RetrackOptions no_refit;
  no_refit.fit.photometric_weight = 0;
  const Result<RetrackResult> outlines_only = RetrackDataset(*source, no_refit, Executor(2));
  ASSERT_TRUE(outlines_only.ok()) << outlines_only.status().message();
  EXPECT_FALSE(outlines_only->similarity_held);
  EXPECT_EQ(outlines_only->photometric_weight, 0.0);
  EXPECT_TRUE(outlines_only->fit.head_from_world->rotation.isApprox(s.rotation, 1e-12));
  EXPECT_NEAR(outlines_only->fit.head_from_world->scale, s.scale, 1e-12);
  EXPECT_TRUE(outlines_only->fit.head_from_world->translation.isApprox(s.translation, 1e-12));
  double sum2 = 0;
  int n = 0;
  for (size_t i = 0; i < d.train.size(); ++i) {
    EXPECT_EQ(d.train[i].camera.world_from_cam(), source->train[i].camera.world_from_cam());
    EXPECT_EQ(d.train[i].file_path, source->train[i].file_path);
    for (int e = 0; e < face::kNumExpressions; ++e)
      if (e != face::kCheekPuff)
        sum2 += std::pow(d.train[i].expression[e] - source->train[i].expression[e], 2), ++n;
  }
  EXPECT_LT(std::sqrt(sum2 / n), 0.25);
  // Detected landmarks: the photometric refit runs by default on the dataset's images and sees the
  // face in every one.
  EXPECT_NE(r->fit.photometric, "off");
  for (const TrackedFrame& f : r->fit.frames) {
    EXPECT_GT(f.photometric_used, 50) << f.ToString();
    EXPECT_LT(f.photometric_rms, 0.1) << f.ToString();
  }
  EXPECT_EQ(RetrackPhotometricWeight(RetrackLandmarks::kDetect), TrackFitOptions().photometric_weight);
  EXPECT_EQ(RetrackPhotometricWeight(RetrackLandmarks::kDatasetDlib), TrackFitOptions().photometric_weight);
  EXPECT_EQ(RetrackPhotometricWeight(RetrackLandmarks::kDatasetModel), 0.0);
  // Turned off: the landmarks alone. The face mesh's place the head within a degree here (0.5);
  // dlib's leave a pitch bias on these small renders (8.8 degrees), which the outlines of the
  // images' alpha masks take in part out (5.3 degrees).
  RetrackOptions landmarks_only;
  landmarks_only.fit.photometric_weight = 0;
  landmarks_only.silhouette_points = 0;
  const Result<RetrackResult> p = RetrackDataset(*source, landmarks_only, Executor(2));
  ASSERT_TRUE(p.ok()) << p.status().message();
  EXPECT_EQ(p->fit.photometric, "off");
  for (const TrackedFrame& f : p->fit.frames) EXPECT_EQ(f.silhouette_used, 0);
  EXPECT_EQ(p->outlined_frames, 0);
  EXPECT_LT(Eigen::AngleAxisd(p->fit.head_from_world->rotation).angle() * 180 / M_PI, 2.0);
  RetrackOptions dlib = landmarks_only;
  dlib.detector = LandmarkDetector::kDlib;
  const Result<RetrackResult> dlib_only = RetrackDataset(*source, dlib, Executor(2));
  ASSERT_TRUE(dlib_only.ok()) << dlib_only.status().message();
  dlib.silhouette_points = -1;
  const Result<RetrackResult> dlib_outlined = RetrackDataset(*source, dlib, Executor(2));
  ASSERT_TRUE(dlib_outlined.ok()) << dlib_outlined.status().message();
  const double dlib_only_deg =
      Eigen::AngleAxisd(dlib_only->fit.head_from_world->rotation).angle() * 180 / M_PI;
  const double dlib_outlined_deg =
      Eigen::AngleAxisd(dlib_outlined->fit.head_from_world->rotation).angle() * 180 / M_PI;
  EXPECT_GT(dlib_only_deg, dlib_outlined_deg + 2.0);
  EXPECT_LT(dlib_outlined_deg, 7.0);
  EXPECT_LT(dlib_only_deg, 15.0);  // loose: catches a fit gone wrong
  EXPECT_EQ(d.test[0].tier, source->test[0].tier);

  // The dataset's own landmarks, in the face model's convention (icef synth's): close to exact.
  RetrackOptions own;
  own.landmarks = RetrackLandmarks::kDatasetModel;
  const Result<RetrackResult> exact = RetrackDataset(*source, own, Executor(2));
  ASSERT_TRUE(exact.ok()) << exact.status().message();
  EXPECT_EQ(exact->fit.photometric, "off");  // exact landmarks: no refit, no silhouettes by default
  for (const TrackedFrame& f : exact->fit.frames) EXPECT_EQ(f.silhouette_used, 0);
  EXPECT_EQ(RetrackSilhouettePoints(RetrackLandmarks::kDetect), 200);
  EXPECT_EQ(RetrackSilhouettePoints(RetrackLandmarks::kDatasetModel), 0);
  EXPECT_LT(Eigen::AngleAxisd(exact->fit.head_from_world->rotation).angle() * 180 / M_PI, 1.0);
  // The training frames' weights against the truth, RMS over the weights a landmark moves.
  auto weight_rms = [&](const Dataset& tracked) {
    double sum = 0;
    for (size_t i = 0; i < d.train.size(); ++i)
      for (int e = 0; e < face::kNumExpressions; ++e)
        if (e != face::kCheekPuff)
          sum += std::pow(tracked.train[i].expression[e] - source->train[i].expression[e], 2);
    return std::sqrt(sum / n);
  };
  const double exact_rms = weight_rms(exact->dataset);
  EXPECT_LT(exact_rms, 0.12);
  // Exact landmarks weigh against the priors at their own tiny noise (0.002 IOD): at the 0.02 of
  // before, the priors pulled the weights the landmarks barely move towards neutral.
  RetrackOptions own_looser = own;
  own_looser.fit.landmark_sigma_iod = 0.02;
  const Result<RetrackResult> looser = RetrackDataset(*source, own_looser, Executor(2));
  ASSERT_TRUE(looser.ok()) << looser.status().message();
  EXPECT_LT(exact_rms, weight_rms(looser->dataset) - 0.005) << exact_rms;
  // Exact landmarks show this subject's own expression style: it is fitted, kept, and the weights
  // read again in it explain the landmarks better than the generic style's.
  ASSERT_TRUE(exact->style_fit.has_value());
  EXPECT_FALSE(exact->style_fit->style_rejected) << exact->style_fit->BriefReport();
  EXPECT_FALSE(exact->style_fit->style.IsGeneric());
  EXPECT_LT(exact->style_fit->rms_iod, exact->style_fit->generic_style_rms_iod);
  RetrackOptions own_generic = own;
  own_generic.fit_style = false;
  const Result<RetrackResult> generic = RetrackDataset(*source, own_generic, Executor(2));
  ASSERT_TRUE(generic.ok()) << generic.status().message();
  EXPECT_FALSE(generic->style_fit.has_value());
  EXPECT_LT(exact->fit.rms_iod, generic->fit.rms_iod)
      << exact->fit.BriefReport() << " vs " << generic->fit.BriefReport();
  // The landmarks written are the styled model's: the trainer's face-model fit (at the tracked
  // weights) finds a style in them again; in the generic dataset's it finds none.
  const auto trainer_fit = [](const Dataset& tracked) {
    std::vector<face::FitFrame> frames;
    for (const Frame& f : tracked.train)
      frames.push_back(face::FitFrame{f.expression, f.landmarks_3d, std::nullopt, std::nullopt});
    face::FaceFitOptions o;
    o.fit_style = true;
    return face::FitFaceModel(frames, o);
  };
  const Result<face::FaceFit> refit_styled = trainer_fit(exact->dataset);
  const Result<face::FaceFit> refit_generic = trainer_fit(generic->dataset);
  ASSERT_TRUE(refit_styled.ok() && refit_generic.ok());
  EXPECT_FALSE(refit_styled->style_rejected) << refit_styled->BriefReport();
  EXPECT_TRUE(refit_generic->style_rejected) << refit_generic->BriefReport();
  // The landmark noise: each source's own unless given (icef track --landmark-sigma), then that.
  EXPECT_LT(RetrackOptions().fit.landmark_sigma_iod, 0);
  EXPECT_EQ(RetrackLandmarkSigma(RetrackLandmarks::kDatasetModel), kRetrackModelLandmarkSigmaIod);
  EXPECT_EQ(RetrackLandmarkSigma(RetrackLandmarks::kDetect), kRetrackLandmarkSigmaIod);
  RetrackOptions own_sigma = own_generic;
  own_sigma.fit.landmark_sigma_iod = RetrackLandmarkSigma(RetrackLandmarks::kDatasetModel);
  const Result<RetrackResult> same = RetrackDataset(*source, own_sigma, Executor(2));
  own_sigma.fit.landmark_sigma_iod = 0.3;  // the priors pull harder: weights nearer neutral
  const Result<RetrackResult> loose = RetrackDataset(*source, own_sigma, Executor(2));
  ASSERT_TRUE(same.ok() && loose.ok());
  double generic_sum = 0, loose_sum = 0;
  for (size_t k = 0; k < generic->fit.frames.size(); ++k) {
    EXPECT_EQ(same->fit.frames[k].expression, generic->fit.frames[k].expression);
    for (int e = 0; e < face::kNumExpressions; ++e)
      generic_sum += generic->fit.frames[k].expression[e], loose_sum += loose->fit.frames[k].expression[e];
  }
  EXPECT_LT(loose_sum, generic_sum - 0.1);

  // RGB frames in front of a background image (NerFace's kind): their outlines come from the
  // difference to it. The dataset's own landmarks keep it quick; the outlines asked for.
  {
    Dataset rgb = *source;
    rgb.root = dir / "rgb";
    fs::create_directories(rgb.root / "images");
    Image bg(source->train[0].camera.width(), source->train[0].camera.height(), 3);
    for (int y = 0; y < bg.height; ++y)
      for (int x = 0; x < bg.width; ++x)
        for (int c = 0; c < 3; ++c) bg.At(x, y, c) = ((x / 8 + y / 8 + c) % 3) * 0.3f + 0.1f;
    ASSERT_TRUE(WritePng(rgb.root / "bg.png", bg).ok());
    rgb.background_file_path = "bg.png";
    for (std::vector<Frame>* frames : {&rgb.train, &rgb.test})
      for (Frame& f : *frames) {
        const Result<Image> rgba = LoadFrameImage(*source, f);
        ASSERT_TRUE(rgba.ok()) << rgba.status().message();
        Image over(rgba->width, rgba->height, 3);
        for (int y = 0; y < over.height; ++y)
          for (int x = 0; x < over.width; ++x)
            for (int c = 0; c < 3; ++c)
              over.At(x, y, c) =
                  rgba->At(x, y, 3) * rgba->At(x, y, c) + (1 - rgba->At(x, y, 3)) * bg.At(x, y, c);
        ASSERT_TRUE(WritePng(rgb.root / f.file_path, over).ok());
        f.neutral_file_path.reset();
      }
    ASSERT_TRUE(SaveDataset(rgb).ok());
    const Result<Dataset> loaded_rgb = LoadDataset(rgb.root);
    ASSERT_TRUE(loaded_rgb.ok()) << loaded_rgb.status().message();
    RetrackOptions outlines = own;
    outlines.silhouette_points = 200;
    std::vector<std::string> lines;
    const Result<RetrackResult> b =
        RetrackDataset(*loaded_rgb, outlines, Executor(2), [&](const std::string& l) { lines.push_back(l); });
    ASSERT_TRUE(b.ok()) << b.status().message();
    for (const TrackedFrame& f : b->fit.frames) EXPECT_GT(f.silhouette_used, 10) << f.ToString();
    EXPECT_LT(Eigen::AngleAxisd(b->fit.head_from_world->rotation).angle() * 180 / M_PI, 1.0);
    EXPECT_TRUE(std::any_of(lines.begin(), lines.end(), [](const std::string& l) {
      return l.find("against the background image bg.png") != std::string::npos;
    }));
  }

  // Written, it loads back with its images; a second write does not replace it.
  ASSERT_TRUE(WriteRetrackedDataset(*r, dir / "out").ok());
  const Result<Dataset> loaded = LoadDataset(dir / "out");
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_EQ(loaded->expression_dim, face::kNumExpressions);
  EXPECT_TRUE(fs::exists(dir / "out" / "track" / "report.json"));
  EXPECT_FALSE(WriteRetrackedDataset(*r, dir / "out").ok());
  fs::remove_all(dir);
}

// The synthetic procedural head re-expressed in ICT-FaceKit with its cameras held (the bench's
// model-mismatch datasets): 53 ARKit-named weights per frame, one head pose among the cameras
// whose mesh's landmarks project onto the frames' own, the jaw read open where the truth opens it.
TEST(DatasetRetrackTest, IctKeepsTheCamerasAndPlacesOneHead) {
  if (!fs::exists(face::IctModel::DefaultPath())) GTEST_SKIP() << "no face model";
  const fs::path dir = fs::temp_directory_path() / ("icef_retrack_ict_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  synth::SynthOptions so;
  so.out_dir = dir / "src";
  so.identity_seed = 6;
  so.num_train = 5;
  so.resolution = 128;
  so.test_views = 1;
  so.novel_per_tier = 1;
  so.render.supersample = 1;
  ASSERT_TRUE(synth::SynthesizeDataset(so, Executor(2)).ok());
  const Result<Dataset> source = LoadDataset(so.out_dir);
  ASSERT_TRUE(source.ok()) << source.status().message();
  RetrackOptions o;
  o.landmarks = RetrackLandmarks::kDatasetModel;
  o.face_model = TrackFaceModel::kIct;
  const Result<RetrackResult> r = RetrackDataset(*source, o, Executor(2));
  ASSERT_TRUE(r.ok()) << r.status().message();
  const Dataset& d = r->dataset;
  const std::shared_ptr<const face::IctModel> ict = face::IctModel::LoadDefault().value();
  EXPECT_EQ(d.expression_names, ict->expression_names());
  EXPECT_EQ(d.expression_dim, 53);
  ASSERT_TRUE(r->fit.head_from_world.has_value());
  // The procedural head's world is its head frame, but its face leans back: nose bridge to chin 22
  // degrees off the vertical, where ICT's is 1.5. ICT's head is turned about x (pitch) to match.
  const Eigen::AngleAxisd turn(r->fit.head_from_world->rotation);
  EXPECT_GT(turn.angle() * 180 / M_PI, 10.0) << r->fit.head_from_world->ToString();
  EXPECT_LT(turn.angle() * 180 / M_PI, 35.0) << r->fit.head_from_world->ToString();
  EXPECT_GT(std::abs(turn.axis().x()), 0.95) << r->fit.head_from_world->ToString();
  EXPECT_LT(r->fit.rms_iod, 0.06) << r->fit.BriefReport();
  const int jaw = ict->ExpressionIndex("jawOpen");
  const std::vector<Frame>* splits[] = {&d.train, &d.test};
  const std::vector<Frame>* sources[] = {&source->train, &source->test};
  double worst_px = 0;
  for (int s = 0; s < 2; ++s) {
    ASSERT_EQ(splits[s]->size(), sources[s]->size());
    for (size_t i = 0; i < splits[s]->size(); ++i) {
      const Frame& f = (*splits[s])[i];
      const Frame& g = (*sources[s])[i];
      EXPECT_EQ(f.camera.world_from_cam(), g.camera.world_from_cam());
      ASSERT_EQ(f.expression.size(), 53u);
      // The truth's jaw (procedural expression 0 is jaw_open) shows in ICT's jawOpen.
      if (g.expression[face::kJawOpen] > 0.6f) EXPECT_GT(f.expression[jaw], 0.2f) << f.file_path;
      if (g.expression[face::kJawOpen] == 0.f) EXPECT_LT(f.expression[jaw], 0.25f) << f.file_path;
      // The fitted landmarks in the world, seen by the frame's own camera, on its landmarks (nose, eyes).
      ASSERT_TRUE(f.landmarks_3d.has_value());
      for (int k : {30, 36, 45}) {
        const auto uv = f.camera.Project((*f.landmarks_3d)[k].cast<double>());
        ASSERT_TRUE(uv.has_value());
        worst_px = std::max(worst_px, (uv->uv - (*g.landmarks_2d)[k].cast<double>()).norm());
      }
    }
  }
  EXPECT_LT(worst_px, 0.1 * so.resolution);
  const Json report = RetrackReportJson(*r);
  EXPECT_EQ(report.at("face_model"), "ict");
  EXPECT_TRUE(report.at("frames")[0].at("expression").contains("jawOpen"));
  fs::remove_all(dir);
}

TEST(DatasetRetrackTest, OutlinesComeFromFramesSpreadOverALongSequence) {
  const std::vector<int> all = SpreadFrames(10, kMaxSilhouetteFrames);
  ASSERT_EQ(all.size(), 10u);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(all[i], i);
  const std::vector<int> spread = SpreadFrames(5000, kMaxSilhouetteFrames);
  ASSERT_EQ(static_cast<int>(spread.size()), kMaxSilhouetteFrames);
  EXPECT_EQ(spread.front(), 0);
  EXPECT_EQ(spread.back(), 4999);
  for (size_t i = 1; i < spread.size(); ++i)
    EXPECT_NEAR(spread[i] - spread[i - 1], 4999.0 / (kMaxSilhouetteFrames - 1), 1.0);
}

TEST(DatasetRetrackTest, LandmarkSourcesParse) {
  for (RetrackLandmarks l :
       {RetrackLandmarks::kDetect, RetrackLandmarks::kDatasetDlib, RetrackLandmarks::kDatasetModel})
    EXPECT_EQ(ParseRetrackLandmarks(RetrackLandmarksName(l)), l);
  EXPECT_FALSE(ParseRetrackLandmarks("mediapipe").has_value());
}

}  // namespace
}  // namespace icef::track
