#include "icef/app/synth_app.h"

#include <cstdio>
#include <vector>

#include "icef/core/progress.h"
#include "icef/io/image.h"
#include "icef/synth/contact_sheet.h"
#include "icef/synth/photo_set.h"

namespace icef {

namespace {

Status RunPhotoSet(const SynthAppOptions& o, const Executor& executor, std::ostream& out) {
  synth::PhotoSetOptions options;
  options.identity_seed = o.options.identity_seed;
  options.generic_style = o.options.generic_style;
  options.num_photos = *o.photos;
  options.render = o.options.render;
  options.background_seed = o.background_seed;
  char x = 0, extra = 0;
  if (std::sscanf(o.photo_size.c_str(), "%d%c%d%c", &options.width, &x, &options.height, &extra) != 3 ||
      (x != 'x' && x != 'X'))
    return Status::Error("--res-photo: expected WxH (e.g. 480x640), got '" + o.photo_size + "'");
  ICEF_RETURN_IF_ERROR(options.Validate());
  ICEF_ASSIGN_OR_RETURN(const std::vector<synth::SynthPhoto> photos,
                        synth::RenderPhotoSet(options, executor));
  ICEF_RETURN_IF_ERROR(synth::WritePhotoSet(options, photos, o.out));
  out << "wrote " << o.out.string() << ": " << photos.size() << " photos (" << options.width << "x"
      << options.height << ") with their truth (" << synth::kPhotoTruthFile << ")\n";
  return Status::Ok();
}

}  // namespace

Status SynthAppOptions::Validate() const {
  if (out.empty()) return Status::Error("--out is required");
  if (photos && !contact_sheet.empty()) return Status::Error("--contact-sheet needs a dataset, not --photos");
  return Status::Ok();
}

Result<synth::SynthOptions> ResolveSynthOptions(const SynthAppOptions& o) {
  synth::SynthOptions options = o.options;
  synth::SceneAxes& axes = options.vary;
  if (o.diverse) axes = synth::SceneAxes::All();
  for (const std::string& a : o.vary) ICEF_RETURN_IF_ERROR(axes.Set(a, true).WithContext("--vary"));
  for (const std::string& a : o.pin) ICEF_RETURN_IF_ERROR(axes.Set(a, false).WithContext("--pin"));
  if (o.resolution_given) axes.resolution = false;
  return options;
}

Status RunSynth(const SynthAppOptions& given, const Executor& executor, std::ostream& out) {
  SynthAppOptions o = given;
  ICEF_ASSIGN_OR_RETURN(o.options, ResolveSynthOptions(given));
  ICEF_RETURN_IF_ERROR(o.Validate());
  if (o.photos) return RunPhotoSet(o, executor, out);
  synth::SynthOptions options = o.options;
  options.out_dir = o.out;
  ICEF_RETURN_IF_ERROR(options.Validate());
  ProgressBar progress("synth", synth::SynthImageCount(options), out, o.interactive);
  Dataset dataset;
  face::StyleGap gap;
  ICEF_RETURN_IF_ERROR(synth::SynthesizeDataset(options, executor, &progress, &dataset, &gap));
  const synth::SynthOptions resolved = synth::ResolveScene(options);
  out << "wrote " << o.out.string() << ": " << dataset.train.size() << " train + " << dataset.test.size()
      << " test frames (" << resolved.resolution << "x" << resolved.resolution << ")\n";
  if (options.vary.Any()) {
    const synth::IdentityParams id = synth::SynthIdentity(options);
    char line[320];
    std::snprintf(
        line, sizeof line,
        "scene (drawn: %s): skin [%.2f %.2f %.2f], key %.2f + ambient %.2f%s, specular %.2f, head scale "
        "%.2f at [%.2f %.2f %.2f], distance %.2f, focal %.2f x res, yaw <= %.0f, pitch <= %.0f (%s)\n",
        options.vary.ToString().c_str(), id.skin_tone[0], id.skin_tone[1], id.skin_tone[2],
        resolved.render.diffuse, resolved.render.ambient, resolved.render.fill > 0 ? " + second light" : "",
        resolved.render.specular, resolved.head_scale, resolved.head_offset[0], resolved.head_offset[1],
        resolved.head_offset[2], resolved.camera_distance, resolved.focal_scale, resolved.max_yaw_deg,
        resolved.max_pitch_deg, synth::kSceneInfoFile);
    out << line;
  }
  char mean[32];
  std::snprintf(mean, sizeof mean, "%.3f", gap.mean);
  out << "expression style: " << (options.generic_style ? "generic (--generic-style)" : "the identity's own")
      << "; style gap " << mean << " (landmark deviation from the generic expressions at weight 1, "
      << "as a fraction of their motion; mean over " << gap.num_measured << " expressions; "
      << synth::kStyleInfoFile << ")\n";
  if (!o.contact_sheet.empty()) {
    ICEF_ASSIGN_OR_RETURN(const Image sheet, synth::MakeContactSheet(dataset));
    ICEF_RETURN_IF_ERROR(WritePng(o.contact_sheet, sheet));
    out << "wrote contact sheet " << o.contact_sheet.string() << "\n";
  }
  return Status::Ok();
}

}  // namespace icef
