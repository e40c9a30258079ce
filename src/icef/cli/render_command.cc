#include <iostream>
#include <memory>

#include "icef/app/render_app.h"
#include "icef/cli/commands.h"
#include "icef/cli/validators.h"

namespace icef::cli {

CommandFn RegisterRender(CLI::App& app) {
  app.description(
      "Render a trained model: colour, depth, region mask M and deformation magnitude as PNGs per frame, "
      "animated GIFs for sequences (and an MP4 with --video), and frames.json with delta, kappa and the "
      "nearest observed expression of "
      "every frame (also printed). Models on the face-model prior (icef-prior, warp-prior) also get "
      "fit_NNN.png: "
      "the fitted face model's outline at the frame's expression over the colour render.");
  auto o = std::make_shared<RenderAppOptions>();
  auto frame = std::make_shared<std::string>();
  auto dataset = std::make_shared<std::string>();
  auto expression_frame = std::make_shared<std::string>();
  auto beta = std::make_shared<std::string>();
  auto sweep = std::make_shared<std::string>();
  auto arkit = std::make_shared<std::string>();
  auto curves = std::make_shared<std::string>();
  auto res = std::make_shared<int>(0);
  app.add_option("model", o->model, "Model directory (or checkpoint file)")->required();
  app.add_option("--out", o->out, "Output directory")->required();
  app.add_option("--dataset", *dataset, "Dataset for --frame / --expression-frame");
  app.add_option("--frame", *frame, "Camera of a dataset frame, SPLIT:INDEX (e.g. test:2)");
  app.add_option("--orbit", o->orbit, "Turntable of N views around the mean training view")
      ->check(kNonNegative);
  app.add_option("--orbit-yaw", o->orbit_yaw, "Turntable yaw half-range, degrees")->capture_default_str();
  app.add_option("--orbit-pitch", o->orbit_pitch, "Camera pitch, degrees")->capture_default_str();
  app.add_option("--res", *res, "Image height of orbit/default cameras, pixels")->check(CLI::Range(8, 4096));
  app.add_option("--expression-frame", *expression_frame, "Expression of a dataset frame, SPLIT:INDEX");
  app.add_option("--beta", *beta, "Expression vector, comma-separated (expression_dim values)");
  app.add_option(
      "--expression", *arkit,
      "The expression by ARKit blendshape names, e.g. jawOpen=0.8,mouthSmileLeft=0.5 (the weights not "
      "named are 0), for a model trained on a dataset from icef track --face-model ict");
  app.add_option(
      "--expressions", *curves,
      "Drive the avatar: ARKit blendshape curves in Live Link Face's CSV layout (Timecode, "
      "BlendShapeCount, EyeBlinkLeft, ..., JawOpen, ...; head and eye rotations ignored), one frame "
      "per row, for a model trained on a dataset from icef track --face-model ict (with --video: "
      "an MP4 at --fps)");
  app.add_option("--set-expression", o->named,
                 "NAME=VALUE on top of the expression, e.g. jaw_open=0.8 (repeatable)");
  app.add_option("--sweep", *sweep, "NAME=VALUE: frames from the expression to VALUE x --sweep-beyond");
  app.add_option("--sweep-frames", o->sweep_frames, "Frames of a sweep")
      ->capture_default_str()
      ->check(CLI::Range(2, 1000));
  app.add_option("--sweep-beyond", o->sweep_beyond, "The sweep ends at this multiple of the target")
      ->capture_default_str();
  auto video = std::make_shared<std::string>();
  app.add_option(
      "--video", *video,
      "Also write the colour frames as an MP4 (H.264) at this path: orbits, sweeps, single frames");
  app.add_option("--fps", o->fps, "Frame rate of --video")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 240.0));
  app.add_option("--threads", o->threads, "Worker threads (0 = all cores)")->check(kNonNegative);
  app.add_option(
      "--set", o->overrides,
      "Override an inference-only model key, model.KEY=VALUE with KEY render.supersample, "
      "render.sample_factor, sampler.num_samples, "
      "render.transmittance_eps or bf16_inference (repeatable; keys fixed by training are refused)");
  return [=]() -> Status {
    RenderAppOptions opts = *o;
    if (!frame->empty()) opts.frame = *frame;
    if (!dataset->empty()) opts.dataset = *dataset;
    if (!expression_frame->empty()) opts.expression_frame = *expression_frame;
    if (!sweep->empty()) opts.sweep = *sweep;
    if (!arkit->empty()) opts.arkit_expression = *arkit;
    if (!curves->empty()) opts.arkit_curves = *curves;
    if (*res > 0) opts.resolution = *res;
    if (!video->empty()) opts.video = *video;
    if (!beta->empty()) {
      ICEF_ASSIGN_OR_RETURN(opts.beta, ParseVector(*beta));
    }
    return RunRender(opts, std::cout).status();
  };
}

}  // namespace icef::cli
