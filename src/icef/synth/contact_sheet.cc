#include "icef/synth/contact_sheet.h"

#include <stb_easy_font.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>
#include <vector>

namespace icef::synth {

Status ContactSheetOptions::Validate() const {
  if (tile < 16 || tile > 1024)
    return Status::Error("tile: expected 16..1024 pixels, got " + std::to_string(tile));
  if (max_columns < 1 || max_columns > 64)
    return Status::Error("max_columns: expected 1..64, got " + std::to_string(max_columns));
  return Status::Ok();
}

std::string ContactSheetOptions::ToString() const {
  return "ContactSheetOptions(tile=" + std::to_string(tile) + ", max_columns=" + std::to_string(max_columns) +
         ", labels=" + (labels ? "true" : "false") + ")";
}

void DrawText(Image& image, int x, int y, const std::string& text, const Vec3f& color) {
  std::vector<char> buffer(text.size() * 300 + 64);
  std::string copy = text;
  unsigned char rgba[4] = {0, 0, 0, 255};
  const int quads = stb_easy_font_print(static_cast<float>(x), static_cast<float>(y), copy.data(), rgba,
                                        buffer.data(), static_cast<int>(buffer.size()));
  const float* v = reinterpret_cast<const float*>(buffer.data());  // 4 vertices of (x, y, z, rgba) per quad
  for (int q = 0; q < quads; ++q) {
    const float* quad = v + q * 16;
    const int x0 = static_cast<int>(quad[0]), y0 = static_cast<int>(quad[1]);
    const int x1 = static_cast<int>(quad[8]), y1 = static_cast<int>(quad[9]);
    for (int py = std::max(0, y0); py < std::min(image.height, y1); ++py)
      for (int px = std::max(0, x0); px < std::min(image.width, x1); ++px)
        for (int c = 0; c < 3 && c < image.channels; ++c) image.At(px, py, c) = color[c];
  }
}

namespace {

// The frame composited over the background and resampled to tile x tile (box filter / nearest).
Image Tile(const Image& frame, const Vec3f& background, int tile) {
  const Image rgb = CompositeOver(frame, background);
  Image out(tile, tile, 3);
  for (int y = 0; y < tile; ++y) {
    for (int x = 0; x < tile; ++x) {
      const int x0 = x * rgb.width / tile, x1 = std::max(x0 + 1, (x + 1) * rgb.width / tile);
      const int y0 = y * rgb.height / tile, y1 = std::max(y0 + 1, (y + 1) * rgb.height / tile);
      Vec3f sum = Vec3f::Zero();
      for (int sy = y0; sy < y1; ++sy)
        for (int sx = x0; sx < x1; ++sx) sum += rgb.Rgb(sx, sy);
      const Vec3f mean = sum / float((x1 - x0) * (y1 - y0));
      for (int c = 0; c < 3; ++c) out.At(x, y, c) = mean[c];
    }
  }
  return out;
}

struct Cell {
  const Dataset* dataset;
  const Frame* frame;
  std::string label;
};
using Rows = std::vector<std::pair<std::string, std::vector<Cell>>>;

// Lays the rows out, one tile per cell, labelled under the tile.
Result<Image> TileRows(const Rows& rows, const ContactSheetOptions& options) {
  const int label_h = options.labels ? 12 : 0, gap = 4;
  const int cell_w = options.tile + gap, cell_h = options.tile + label_h + gap;
  int columns = 1;
  for (const auto& r : rows)
    columns = std::max(columns, std::min<int>(options.max_columns, static_cast<int>(r.second.size())));
  Image sheet(columns * cell_w + gap, static_cast<int>(rows.size()) * cell_h + gap, 3, 1.f);
  for (size_t r = 0; r < rows.size(); ++r) {
    const auto& cells = rows[r].second;
    for (int c = 0; c < std::min<int>(columns, static_cast<int>(cells.size())); ++c) {
      ICEF_ASSIGN_OR_RETURN(const Image frame, LoadFrameImage(*cells[c].dataset, *cells[c].frame));
      const Image tile = Tile(frame, cells[c].dataset->background, options.tile);
      const int ox = gap + c * cell_w, oy = gap + static_cast<int>(r) * cell_h;
      for (int y = 0; y < options.tile; ++y)
        for (int x = 0; x < options.tile; ++x)
          for (int ch = 0; ch < 3; ++ch) sheet.At(ox + x, oy + y, ch) = tile.At(x, y, ch);
      if (options.labels)
        DrawText(sheet, ox + 1, oy + options.tile + 2, cells[c].label, Vec3f(0.1f, 0.1f, 0.1f));
    }
  }
  return sheet;
}

}  // namespace

Result<Image> MakeContactSheet(const Dataset& dataset, const ContactSheetOptions& options) {
  ICEF_RETURN_IF_ERROR(options.Validate());
  Rows rows;
  std::vector<Cell> train;
  for (size_t i = 0; i < dataset.train.size(); ++i)
    train.push_back({&dataset, &dataset.train[i], "train " + std::to_string(i)});
  rows.push_back({"train", train});
  // Neutral test views (distinct neutral_file_path values, in order of appearance).
  std::vector<Frame> neutrals;
  std::set<std::string> seen;
  for (const Frame& f : dataset.test) {
    if (!f.neutral_file_path || !seen.insert(*f.neutral_file_path).second) continue;
    Frame n = f;
    n.file_path = *f.neutral_file_path;
    neutrals.push_back(n);
  }
  std::vector<Cell> neutral_row;
  for (size_t i = 0; i < neutrals.size(); ++i)
    neutral_row.push_back({&dataset, &neutrals[i], "neutral v" + std::to_string(i)});
  if (!neutral_row.empty()) rows.push_back({"neutral", neutral_row});
  // One tile per distinct test expression, per tier; views taken in turn.
  for (Tier tier : {Tier::kObserved, Tier::kNear, Tier::kModerate, Tier::kFar}) {
    std::vector<Cell> row;
    const std::vector<float>* last = nullptr;
    int expression_count = 0;
    for (size_t i = 0; i < dataset.test.size(); ++i) {
      const Frame& f = dataset.test[i];
      if (!f.tier || *f.tier != tier) continue;
      if (last && *last == f.expression) continue;
      // First frame of a new expression: pick its (expression_count mod run length)-th view.
      size_t run = i;
      while (run < dataset.test.size() && dataset.test[run].expression == f.expression) ++run;
      const size_t pick = i + static_cast<size_t>(expression_count) % (run - i);
      last = &f.expression;
      ++expression_count;
      char label[64];
      std::snprintf(label, sizeof label, "%s d=%.2f", TierName(tier), dataset.test[pick].delta.value_or(0.0));
      row.push_back({&dataset, &dataset.test[pick], label});
    }
    if (!row.empty()) rows.push_back({TierName(tier), row});
  }
  return TileRows(rows, options);
}

Result<Image> MakeTrainingSheet(const std::vector<Dataset>& datasets, const ContactSheetOptions& options) {
  ICEF_RETURN_IF_ERROR(options.Validate());
  Rows rows;
  for (const Dataset& d : datasets) {
    std::vector<Cell> row;
    const std::string name =
        d.root.filename().empty() ? d.root.parent_path().filename().string() : d.root.filename().string();
    for (size_t i = 0; i < d.train.size(); ++i)
      row.push_back({&d, &d.train[i], i == 0 ? name : "train " + std::to_string(i)});
    rows.push_back({name, row});
  }
  return TileRows(rows, options);
}

}  // namespace icef::synth
