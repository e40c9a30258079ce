// icef track PHOTOS... --out DATASET [--res N] [--focal PX] [--test N] [--skip-bad] [--threads N]
// icef track VIDEO --frames K --test N --out DATASET [--every N | --max-frames N]
// icef track DATASET --keep-cameras --out NEW
// icef track VIDEO --curves CURVES.csv
// From a handful of photos of one person to a dataset (docs/design.md §8): app/track_app.h does the work.
#include <iostream>
#include <memory>
#include <string>

#include "icef/app/landmarks_app.h"
#include "icef/app/track_app.h"
#include "icef/cli/commands.h"
#include "icef/cli/validators.h"
#include "icef/core/progress.h"

namespace icef::cli {

namespace {

constexpr const char* kTrackDescription =
    "Turn photos or a video of one person into a dataset: detects the face and its 68 landmarks in each "
    "photo (exactly one face per photo), fits the face model to all photos at once (shared identity; per "
    "photo a head pose and expression weights), crops a square around the head, masks the head (GrabCut "
    "seeded by the fitted head, with what MediaPipe's selfie segmentation calls background as sure "
    "background), refits the face model to the landmarks and each mask's outline, refines each photo's "
    "expression and pose on the photos' colours (the photometric refit), crops and masks again, and writes "
    "the dataset in the fitted head's frame, with track/overlay_NNN.png to check the fit and "
    "track/report.json. Then: icef train DATASET, icef render --sweep.\n"
    "With --keep-cameras, re-express an existing dataset (NerFace, instant-ngp, any expression space) in the "
    "face model's expressions: same cameras and images, the face model fitted to every frame's landmarks, "
    "with track/overlay_<split>_NNN.png to check the fit (every frame; at most 100, spread over a longer "
    "sequence).\n"
    "With --curves, a video's expressions as ARKit curves to drive an avatar with: ICT-FaceKit fitted to "
    "every frame's landmarks (one identity, the driving person's, kept out of the curves), written in Live "
    "Link Face's CSV layout (Timecode, BlendShapeCount, the ARKit blendshapes, HeadYaw, HeadPitch, "
    "HeadRoll in radians). Then: icef render MODEL --expressions CURVES.csv --video drive.mp4.";

// photos ... --skip-bad: what is tracked and what the dataset holds.
void AddInputOptions(CLI::App& app, TrackCommandOptions& o) {
  app.add_option(
      "photos", o.app.photos,
      "Photos (PNG/JPEG) or directories of photos, or one video (.mp4, .mov, .mkv, .avi, .webm, .m4v)");
  app.add_option("--out", o.app.out, "Dataset directory to create (must not exist, or be empty)");
  app.add_option("--curves", o.curves,
                 "VIDEO: write every frame's ARKit expression weights and head rotation to this CSV (Live "
                 "Link Face's layout) instead of a dataset; --every thins the frames, --max-frames keeps the "
                 "first N; a frame without one face repeats the nearest tracked frame's curves");
  app.add_option("--res", o.app.track.resolution,
                 "Side of the square dataset images in pixels (default 256)");
  app.add_option(
      "--focal", o.focal,
      "Focal length in pixels of the photos (default: the EXIF 35 mm-equivalent focal length, else a 35 "
      "mm-equivalent lens: 0.81 x the photo's diagonal)");
  app.add_option(
         "--test", o.app.track.num_test,
         "Hold out N test frames: the last N photos; with --frames, N of the frames not chosen for training, "
         "spread evenly in time order (default: 0; with --frames, all of them)")
      ->check(kNonNegative);
  app.add_option(
         "--frames", o.app.track.num_train,
         "Choose N training frames for coverage of head pose and expression (the most frontal, neutral one "
         "first, then each time the frame farthest from those chosen; no blinks unless --allow-blink, no "
         "frame much blurrier than the median) instead of taking all photos but the --test ones")
      ->check(kNonNegative);
  app.add_flag("--allow-blink", o.app.track.allow_blink,
               "With --frames: a frame with an eye closed may be chosen");
  app.add_option("--every", o.app.every, "A video: track every N-th decoded frame")->check(kPositive);
  app.add_option("--max-frames", o.app.max_frames,
                 "A video: track at most N frames, spread evenly over the whole video (default " +
                     std::to_string(kDefaultVideoFrames) + " when --every is not given)")
      ->check(kPositive);
  app.add_flag(
      "--skip-bad", o.app.track.skip_bad,
      "Skip photos without exactly one face (default: stop, naming the photo, and write nothing; a video's "
      "frames are always skipped so)");
}

// --segmentation ... --generic-style: the mask, and the mode that keeps a dataset's cameras.
void AddModeOptions(CLI::App& app, TrackCommandOptions& o) {
  app.add_option(
         "--face-model", o.face_model,
         "The face model fitted: procedural (the built-in procedural head, its 11 expressions; fits the "
         "landmarks, the masks' outlines and the colours; default) or ict (ICT-FaceKit, learned from "
         "scans: 100 identity modes, 53 ARKit-named expressions; fits the landmarks; the dataset's "
         "expressions are its 53 weights; with --keep-cameras, one head pose among the dataset's cameras)")
      ->check(CLI::IsMember({"procedural", "ict"}));
  app.add_option(
         "--segmentation", o.segmentation,
         "The dataset's alpha mask: selfie (GrabCut seeded by the fitted head, with what MediaPipe's selfie "
         "segmentation calls background as sure background; default; scripts/install-deps.sh installs its "
         "weights), none (GrabCut alone) or selfie-only (the selfie segmentation's person: shoulders, arms "
         "and hands included, no GrabCut). The refit's silhouettes always come from GrabCut alone")
      ->check(CLI::IsMember({"selfie", "none", "selfie-only"}));
  app.add_flag(
      "--keep-cameras", o.app.keep_cameras,
      "PHOTOS is one dataset: keep its cameras and images, re-express its expressions in the face model's");
  app.add_option("--landmarks", o.landmarks,
                 "With --keep-cameras: whose 2D landmarks to fit: detect (--detector's, in every frame; "
                 "default), dlib (the dataset's own landmarks_2d in dlib's convention, from icef landmarks), "
                 "model (the dataset's own, in the face model's convention, as icef synth writes them)");
  app.add_flag(
      "--generic-style", o.generic_style,
      "With --keep-cameras --landmarks model: read every weight in the face model's generic expression "
      "style. By default the subject's own style (how far the jaw opens per unit, where it hinges, how wide "
      "the smile is, ...) is read off those exact landmarks first, the weights are read in it, and the "
      "dataset's 3D landmarks are the styled model's, so that icef train finds the style again "
      "(docs/tracking.md)");
}

// --silhouette-points ... --silhouette-region: what the refit fits besides the landmarks.
void AddRefitOptions(CLI::App& app, TrackCommandOptions& o) {
  app.add_option(
         "--silhouette-points", o.silhouette_points,
         "Refit each photo's pose, expression and the shape with this many points of its mask's edge beside "
         "the landmarks (0 = landmarks only; default 200); with --keep-cameras, the edge of each frame's "
         "alpha mask, or of its difference to the dataset's background image (NerFace's bg/), in the frames "
         "that have one (default 200 for dlib's landmarks and 0 for --landmarks model, which place the head "
         "already)")
      ->check(kNonNegative);
  app.add_option(
         "--photometric-weight", o.photometric_weight,
         "Refine each photo's expression and pose on the photos themselves: points of the neutral face, "
         "carried into every photo by the fitted warp and pose, must find the same colour there; their "
         "weight against the landmarks (0 = landmarks and outline only; default 16; with --keep-cameras 0 "
         "for --landmarks model, which are exact, and for dlib's landmarks 64 where the frames' outlines "
         "place the head, which the refit then holds, else 16: docs/tracking.md)")
      ->check(kNonNegative);
  app.add_option(
         "--silhouette-region", o.silhouette_region,
         "Which part of the mask's edge the refit uses: face (where it touches the head between the chin and "
         "the brows with skin just inside it; default: a real head's crown and often its cheeks are hair, "
         "its neck runs into clothes) or head (the whole outline: heads without hair, such as icef synth's, "
         "whose hair is painted on)")
      ->check(CLI::IsMember({"face", "head"}));
}

// --threads ... --calibrate-detector: the detector and the machine.
void AddDetectorOptions(CLI::App& app, TrackCommandOptions& o) {
  app.add_option("--threads", o.app.threads, "Worker threads (0 = all cores)");
  app.add_option("--predictor", o.app.predictor,
                 "dlib 68-point shape predictor (default " + DefaultShapePredictorPath() + ")");
  app.add_option(
         "--detector", o.detector,
         "Whose 68 landmarks the fit reads from the images: mesh (MediaPipe's face mesh, in a crop placed by "
         "dlib's face; default; scripts/install-deps.sh installs its weights) or dlib (dlib's shape "
         "predictor, averaged over shifted boxes). With --keep-cameras: for --landmarks detect")
      ->check(CLI::IsMember({"dlib", "mesh"}));
  app.add_option(
         "--landmark-sigma", o.landmark_sigma,
         "The landmarks' noise in inter-ocular distances, which the priors are balanced against (default: "
         "0.05; with --keep-cameras 0.1, and 0.002 for --landmarks model, which are exact; docs/tracking.md)")
      ->check(kPositive);
  app.add_flag(
      "--calibrate-detector", o.calibrate_detector,
      "Developer: measure where the detector (--detector) puts its landmarks on the face model (renders of "
      "validation identities) and print the table of src/icef/track/detector_landmarks.inc (dlib) or "
      "mesh_landmarks.inc (mesh)");
}

}  // namespace

CommandFn RegisterTrack(CLI::App& app) {
  auto options = std::make_shared<TrackCommandOptions>();
  app.description(kTrackDescription);
  AddInputOptions(app, *options);
  AddModeOptions(app, *options);
  AddRefitOptions(app, *options);
  AddDetectorOptions(app, *options);
  return [options]() {
    TrackCommandOptions o = *options;
    o.app.interactive = StdoutIsTerminal();
    return RunTrackCommand(o, std::cout, std::cerr);
  };
}

}  // namespace icef::cli
