// `icef synth --out DIR ...`: renders a synthetic ground-truth dataset of one procedural identity
// (synth/synthesize.h) and prints the identity's expression-style gap (also in DIR/style.json),
// optionally with a contact sheet. With `--photos N` instead: N photos of the identity at random
// head poses, sizes, positions and expressions over procedural backgrounds, with their truth
// (DIR/photos/, DIR/truth/alpha_NNN.png, DIR/truth/truth.json, DIR/style.json; synth/photo_set.h),
// for testing a face tracker.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/synth/synthesize.h"

namespace icef {

struct SynthAppOptions {
  synth::SynthOptions options;  // the subject and the dataset (out_dir is taken from `out`)
  std::filesystem::path out;    // output dataset (or photo-set) directory
  std::filesystem::path
      contact_sheet;          // dataset mode: also write a labelled contact sheet PNG here (empty: none)
  std::optional<int> photos;  // photo-set mode: write this many photos instead of a dataset
  std::string photo_size = "480x640";  // photo-set mode: photo size WxH
  uint64_t background_seed =
      0;                 // photo-set mode: seed of the backgrounds (0: derived from the identity seed)
  bool diverse = false;  // draw every scene axis per identity seed (options.vary = All())
  std::vector<std::string> vary;  // scene axes to draw per identity seed, on top of options.vary
  std::vector<std::string> pin;   // scene axes kept at the classic values (after diverse and vary)
  bool resolution_given = false;  // --res was given: it pins the resolution axis
  bool interactive = false;       // redraw the progress bar in place (stdout is a terminal)

  // Errors name the option (--out, --contact-sheet).
  Status Validate() const;
};

// options.options with the scene axes diverse, vary, pin and resolution_given select; errors name
// the option and the unknown axis.
Result<synth::SynthOptions> ResolveSynthOptions(const SynthAppOptions& options);

// Writes the dataset (or photo set) and prints what was written on `out`.
Status RunSynth(const SynthAppOptions& options, const Executor& executor, std::ostream& out);

}  // namespace icef
