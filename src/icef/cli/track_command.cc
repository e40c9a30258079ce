// icef track PHOTOS... --out DATASET [--res N] [--focal PX] [--test N] [--skip-bad] [--threads N]
// icef track VIDEO --frames K --test N --out DATASET [--every N | --max-frames N]
// icef track DATASET --keep-cameras --out NEW
// From a handful of photos of one person to a dataset (docs/design.md §8): app/track_app.h does the work.
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "icef/app/detector_calibration.h"
#include "icef/app/track_app.h"
#include "icef/cli/commands.h"
#include "icef/cli/validators.h"
#include "icef/core/progress.h"
#include "icef/landmarks/face_landmark_detector.h"

namespace icef::cli {

CommandFn RegisterTrack(CLI::App& app) {
  auto options = std::make_shared<TrackAppOptions>();
  auto focal = std::make_shared<double>(0);
  app.description(
      "Turn photos or a video of one person into a dataset: detects the face and its 68 landmarks in each photo (exactly one "
      "face per photo), fits the face model to all photos at once (shared identity; per photo a head pose and "
      "expression weights), crops a square around the head, masks the head (GrabCut seeded by the fitted head, "
      "with what MediaPipe's selfie segmentation calls background as sure background), "
      "refits the face model to the landmarks and each mask's outline, refines each photo's expression and pose on "
      "the photos' colours (the photometric refit), crops and masks again, and writes the dataset in the fitted "
      "head's frame, with track/overlay_NNN.png to check the fit and "
      "track/report.json. Then: icef train DATASET, icef render --sweep.\n"
      "With --keep-cameras, re-express an existing dataset (NerFace, instant-ngp, any expression space) in the face "
      "model's expressions: same cameras and images, the face model fitted to every frame's landmarks, with "
      "track/overlay_<split>_NNN.png to check the fit (every frame; at most 100, spread over a longer sequence).");
  app.add_option("photos", options->photos,
                 "Photos (PNG/JPEG) or directories of photos, or one video (.mp4, .mov, .mkv, .avi, .webm, .m4v)");
  app.add_option("--out", options->out, "Dataset directory to create (must not exist, or be empty)");
  app.add_option("--res", options->track.resolution, "Side of the square dataset images in pixels (default 256)");
  app.add_option("--focal", *focal,
                 "Focal length in pixels of the photos (default: the EXIF 35 mm-equivalent focal length, else a "
                 "35 mm-equivalent lens: 0.81 x the photo's diagonal)");
  app.add_option("--test", options->track.num_test,
                 "Hold out N test frames: the last N photos; with --frames, N of the frames not chosen for training, "
                 "spread evenly in time order (default: 0; with --frames, all of them)")
      ->check(kNonNegative);
  app.add_option("--frames", options->track.num_train,
                 "Choose N training frames for coverage of head pose and expression (the most frontal, neutral one "
                 "first, then each time the frame farthest from those chosen; no blinks unless --allow-blink, no "
                 "frame much blurrier than the median) instead of taking all photos but the --test ones")
      ->check(kNonNegative);
  app.add_flag("--allow-blink", options->track.allow_blink, "With --frames: a frame with an eye closed may be chosen");
  app.add_option("--every", options->every, "A video: track every N-th decoded frame")->check(kPositive);
  app.add_option("--max-frames", options->max_frames,
                 "A video: track at most N frames, spread evenly over the whole video (default " +
                     std::to_string(kDefaultVideoFrames) + " when --every is not given)")
      ->check(kPositive);
  app.add_flag("--skip-bad", options->track.skip_bad,
               "Skip photos without exactly one face (default: stop, naming the photo, and write nothing; a video's "
               "frames are always skipped so)");
  auto segmentation = std::make_shared<std::string>("selfie");
  app.add_option("--segmentation", *segmentation,
                 "The dataset's alpha mask: selfie (GrabCut seeded by the fitted head, with what MediaPipe's selfie "
                 "segmentation calls background as sure background; default; scripts/install-deps.sh installs its "
                 "weights), none (GrabCut alone) or selfie-only (the selfie segmentation's person: shoulders, arms and "
                 "hands included, no GrabCut). The refit's silhouettes always come from GrabCut alone")
      ->check(CLI::IsMember({"selfie", "none", "selfie-only"}));
  app.add_flag("--keep-cameras", options->keep_cameras,
               "PHOTOS is one dataset: keep its cameras and images, re-express its expressions in the face model's");
  auto landmarks = std::make_shared<std::string>("detect");
  app.add_option("--landmarks", *landmarks,
                 "With --keep-cameras: whose 2D landmarks to fit: detect (--detector's, in every frame; default), dlib (the "
                 "dataset's own landmarks_2d in dlib's convention, from icef landmarks), model (the dataset's own, in the face "
                 "model's convention, as icef synth writes them)");
  auto generic_style = std::make_shared<bool>(false);
  app.add_flag("--generic-style", *generic_style,
               "With --keep-cameras --landmarks model: read every weight in the face model's generic expression style. "
               "By default the subject's own style (how far the jaw opens per unit, where it hinges, how wide the "
               "smile is, ...) is read off those exact landmarks first, the weights are read in it, and the dataset's "
               "3D landmarks are the styled model's, so that icef train finds the style again (docs/tracking.md)");
  auto silhouette_points = std::make_shared<int>(-1);  // -1: the mode's default
  app.add_option(
         "--silhouette-points", *silhouette_points,
         "Refit each photo's pose, expression and the shape with this many points of its mask's edge "
         "beside the landmarks (0 = landmarks only; default 200); with --keep-cameras, the edge of each "
         "frame's alpha mask, or of its difference to the dataset's background image (NerFace's bg/), in "
         "the frames that have one (default 200 for dlib's landmarks and 0 for --landmarks model, which "
         "place the head already)")
      ->check(kNonNegative);
  auto photometric = std::make_shared<double>(-1);  // -1: the mode's default
  app.add_option(
         "--photometric-weight", *photometric,
         "Refine each photo's expression and pose on the photos themselves: points of the neutral face, "
         "carried into every photo by the fitted warp and pose, must find the same colour there; their "
         "weight against the landmarks (0 = landmarks and outline only; default 16; with --keep-cameras 0 "
         "for "
         "--landmarks model, which are exact, and for dlib's landmarks 64 where the frames' outlines place "
         "the head, which the refit then holds, else 16: docs/tracking.md)")
      ->check(kNonNegative);
  auto region = std::make_shared<std::string>("face");
  app.add_option("--silhouette-region", *region,
                 "Which part of the mask's edge the refit uses: face (where it touches the head between the chin and "
                 "the brows with skin just inside it; default: a real head's crown and often its cheeks are hair, its "
                 "neck runs into clothes) or head (the whole outline: heads without hair, such as icef synth's, whose hair "
                 "is painted on)")
      ->check(CLI::IsMember({"face", "head"}));
  app.add_option("--threads", options->threads, "Worker threads (0 = all cores)");
  app.add_option("--predictor", options->predictor,
                 "dlib 68-point shape predictor (default " + std::string(kDefaultShapePredictorPath) + ")");
  auto detector = std::make_shared<std::string>("mesh");
  app.add_option("--detector", *detector,
                 "Whose 68 landmarks the fit reads from the images: mesh (MediaPipe's face mesh, in a crop placed by "
                 "dlib's face; default; scripts/install-deps.sh installs its weights) or dlib (dlib's shape predictor, "
                 "averaged over shifted boxes). With --keep-cameras: for --landmarks detect")
      ->check(CLI::IsMember({"dlib", "mesh"}));
  auto landmark_sigma = std::make_shared<double>(-1);
  app.add_option(
         "--landmark-sigma", *landmark_sigma,
         "The landmarks' noise in inter-ocular distances, which the priors are balanced against (default: "
         "0.05; with --keep-cameras 0.1, and 0.002 for --landmarks model, which are exact; docs/tracking.md)")
      ->check(kPositive);
  auto calibrate = std::make_shared<bool>(false);
  app.add_flag("--calibrate-detector", *calibrate,
               "Developer: measure where the detector (--detector) puts its landmarks on the face model (renders of "
               "validation identities) and print the table of src/icef/track/detector_landmarks.inc (dlib) or "
               "mesh_landmarks.inc (mesh)");
  return [options, focal, calibrate, detector, landmark_sigma, landmarks, region, photometric, silhouette_points,
          segmentation, generic_style, &app]() -> Status {
    options->fit_style = !*generic_style;
    options->track.fit.silhouette_face_only = *region == "face";
    options->track.segmentation = *segmentation == "none"     ? track::TrackOptions::Segmentation::kNone
                                  : *segmentation == "selfie" ? track::TrackOptions::Segmentation::kSelfie
                                                              : track::TrackOptions::Segmentation::kSelfieOnly;
    if (*photometric >= 0) {
      options->track.fit.photometric_weight = *photometric;
    } else if (options->keep_cameras) {
      options->track.fit.photometric_weight = track::RetrackOptions().fit.photometric_weight;
    }
    if (*silhouette_points >= 0) {
      options->track.silhouette_points = *silhouette_points;
    } else if (options->keep_cameras) {
      options->track.silhouette_points = track::RetrackOptions().silhouette_points;  // the source's default
    }
    const auto parsed = track::ParseRetrackLandmarks(*landmarks);
    if (!parsed) return Status::Error("--landmarks: expected detect, dlib or model, got \"" + *landmarks + "\"");
    options->landmarks = *parsed;
    if (*generic_style && !(options->keep_cameras && options->landmarks == track::RetrackLandmarks::kDatasetModel))
      return Status::Error("--generic-style: only with --keep-cameras --landmarks model (the other landmarks are always "
                           "read in the generic style)");
    options->track.fit.detector = *detector == "mesh" ? track::LandmarkDetector::kMesh : track::LandmarkDetector::kDlib;
    if (*landmark_sigma > 0) {
      options->track.fit.landmark_sigma_iod = *landmark_sigma;
    } else if (options->keep_cameras) {
      options->track.fit.landmark_sigma_iod = track::RetrackOptions().fit.landmark_sigma_iod;
    }
    if (*calibrate) {
      const std::vector<uint64_t> validation_seeds = {101, 102, 103, 104, 105, 106, 107, 108, 109, 110, 111, 112};
      ICEF_ASSIGN_OR_RETURN(const DetectorCalibration c,
                            CalibrateDetector(validation_seeds, Executor(options->threads), &std::cerr, *detector == "mesh"));
      PrintDetectorTable(c, std::cout);
      return Status::Ok();
    }
    if (options->photos.empty()) return Status::Error("icef track: give the photos (or a dataset with --keep-cameras)");
    if (options->out.empty()) return Status::Error("icef track: --out DATASET is required");
    if (app.count("--focal")) options->track.focal = *focal;
    options->interactive = StdoutIsTerminal();
    return RunTrack(*options, std::cout);
  };
}

}  // namespace icef::cli
