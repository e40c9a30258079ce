#include "icef/study/real_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <sstream>

#include "icef/io/atomic_file.h"
#include "icef/io/image.h"
#include "icef/study/report.h"

namespace fs = std::filesystem;

namespace icef::eval {

namespace {

std::string Fmt(const std::optional<double>& v, const char* format) {
  if (!v) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, format, *v);
  return buf;
}

std::string LatexEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '_' || c == '%' || c == '&' || c == '#' || c == '$') out += '\\';
    out += c;
  }
  return out;
}

// Runs in report order: source (as given), K, method (as given).
std::vector<const RealRunRecord*> Ordered(const std::vector<RealRunRecord>& runs,
                                          const RealReportContext& context) {
  std::vector<const RealRunRecord*> out;
  for (const RealRunRecord& r : runs) out.push_back(&r);
  auto source_rank = [&](const std::string& name) {
    for (size_t i = 0; i < context.sources.size(); ++i)
      if (context.sources[i].name == name) return static_cast<int>(i);
    return static_cast<int>(context.sources.size());
  };
  std::stable_sort(out.begin(), out.end(), [&](const RealRunRecord* a, const RealRunRecord* b) {
    if (source_rank(a->source) != source_rank(b->source))
      return source_rank(a->source) < source_rank(b->source);
    return a->k < b->k;
  });
  return out;
}

// One row of images side by side (RGB), white between.
Image Row(const std::vector<Image>& images, int gap) {
  int width = 0, height = 0;
  for (const Image& im : images) {
    width += im.width + gap;
    height = std::max(height, im.height);
  }
  Image row(std::max(width - gap, 1), std::max(height, 1), 3, 1.f);
  int x0 = 0;
  for (const Image& im : images) {
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x)
        for (int c = 0; c < 3; ++c) row.At(x0 + x, y, c) = im.At(x, y, c);
    x0 += im.width + gap;
  }
  return row;
}

Image Stack(const std::vector<Image>& rows, int gap) {
  int width = 0, height = 0;
  for (const Image& r : rows) {
    width = std::max(width, r.width);
    height += r.height + gap;
  }
  Image sheet(std::max(width, 1), std::max(height - gap, 1), 3, 1.f);
  int y0 = 0;
  for (const Image& r : rows) {
    for (int y = 0; y < r.height; ++y)
      for (int x = 0; x < r.width; ++x)
        for (int c = 0; c < 3; ++c) sheet.At(x, y0 + y, c) = r.At(x, y, c);
    y0 += r.height + gap;
  }
  return sheet;
}

// Plots of face PSNR and real_expr_gain against K: one line per (source, method).
Result<std::vector<std::string>> WriteRealPlots(const fs::path& dir,
                                                const std::vector<const RealRunRecord*>& runs,
                                                std::string* note) {
  std::vector<std::string> pngs;
  std::map<std::string, std::vector<const RealRunRecord*>> lines;  // "source / method" -> runs by K
  for (const RealRunRecord* r : runs) lines[r->source + " / " + r->method].push_back(r);
  if (lines.empty()) return pngs;
  const fs::path plot_dir = dir / "plots";
  std::error_code ec;
  fs::create_directories(plot_dir, ec);
  if (ec) return Status::Error(plot_dir.string() + ": cannot create directory: " + ec.message());
  const bool have_gnuplot = HaveGnuplot();
  const std::vector<std::pair<std::string, std::string>> metrics = {
      {"face_psnr", "face PSNR against the held-out photo (dB, higher = better)"},
      {"real_expr_gain", "real_expr_gain (1 = the tracked expression closes the gap, 0 = no change)"}};
  for (const auto& [metric, label] : metrics) {
    std::ostringstream dat, plot;
    dat << "# " << metric << ": one block per source / method; columns: K, mean over held-out frames\n";
    plot << "set xlabel \"K (training frames)\"\nset ylabel \"" << label << "\"\nset grid\nset key below\n"
         << "set xtics (3, 5, 10)\nset offsets 0.3, 0.3, 0, 0\nplot ";
    int block = 0;
    for (const auto& [line, list] : lines) {
      dat << "# " << line << "\n";
      for (const RealRunRecord* r : list) {
        const Json means = r->metrics.means.ToJson();
        const double v = means[metric].is_number() ? means[metric].get<double>() : NAN;
        dat << r->k << " " << v << "\n";
      }
      dat << "\n\n";
      plot << (block ? ", " : "") << "'" << metric << ".dat' index " << block
           << " using 1:2 with linespoints lw 2 pt 7 title \"" << line << "\"";
      ++block;
    }
    plot << "\n";
    ICEF_RETURN_IF_ERROR(WriteFileAtomic(plot_dir / (metric + ".dat"), dat.str()));
    std::ostringstream gp;
    gp << "# gnuplot " << metric << ".gp (run in this directory) draws " << metric << ".png, .svg and .pdf\n"
       << "set terminal pngcairo noenhanced size 640,420 font \"sans,9\"\nset output \"" << metric
       << ".png\"\n"
       << plot.str() << "set terminal svg noenhanced size 640,420 font \"sans,9\"\nset output \"" << metric
       << ".svg\"\n"
       << plot.str() << "set terminal pdfcairo noenhanced size 4.3in,2.8in font \"sans,7\"\nset output \""
       << metric << ".pdf\"\n"
       << plot.str() << "unset output\n";
    ICEF_RETURN_IF_ERROR(WriteFileAtomic(plot_dir / (metric + ".gp"), gp.str()));
    if (!have_gnuplot) continue;
    ICEF_RETURN_IF_ERROR(RunGnuplot(plot_dir, metric));
    pngs.push_back("plots/" + metric + ".png");
  }
  if (!have_gnuplot && note)
    *note = "Plots not drawn: gnuplot is not installed; run `gnuplot X.gp` in plots/.";
  return pngs;
}

}  // namespace

std::string RealRunRecord::Name() const { return source + "_k" + std::to_string(k) + "_" + method; }

Json RealRunRecord::ToJson() const {
  return Json{{"source", source},
              {"k", k},
              {"method", method},
              {"train_steps", train_steps},
              {"train_seconds", train_seconds},
              {"dataset", dataset.string()},
              {"metrics", metrics.ToJson()}};
}

Result<RealRunRecord> RealRunRecord::FromJson(const Json& j, const std::string& where) {
  if (!j.is_object()) return Status::Error(where + ": expected an object");
  RealRunRecord r;
  if (!j.contains("source") || !j["source"].is_string())
    return Status::Error(where + ".source: expected a string");
  if (!j.contains("k") || !j["k"].is_number_integer())
    return Status::Error(where + ".k: expected an integer");
  if (!j.contains("method") || !j["method"].is_string())
    return Status::Error(where + ".method: expected a string");
  if (!j.contains("metrics")) return Status::Error(where + ".metrics: missing");
  r.source = j["source"].get<std::string>();
  r.k = j["k"].get<int>();
  r.method = j["method"].get<std::string>();
  r.train_steps = j.value("train_steps", int64_t{0});
  r.train_seconds = j.value("train_seconds", 0.0);
  r.dataset = j.value("dataset", std::string());
  ICEF_ASSIGN_OR_RETURN(r.metrics, RealEvalResult::FromJson(j["metrics"], where + ".metrics"));
  return r;
}

std::string RealReportMarkdown(const std::vector<RealRunRecord>& runs, const RealReportContext& context,
                               const std::vector<std::string>& images) {
  std::ostringstream md;
  md << "# Real media: self-reenactment on held-out frames\n\n"
     << "Each source is tracked once (`icef track`); for each K the avatar trains on the K frames that cover "
        "head "
        "pose and expression best and renders every held-out frame at its tracked camera with its tracked "
        "expression. Everything is measured against the real photo (docs/design.md §9): face = the hull of "
        "the "
        "frame's 68 landmarks, head = its mask. `real_expr_gain`: how much of the error in the "
        "mouth/eye/brow "
        "region the tracked expression removes against a render of the same camera with the nearest training "
        "frame's expression (1 = all, 0 = none, < 0 = worse). `face PSNR, still`: that nearest-expression "
        "render's face PSNR (an avatar that does not move). `track RMS`: the held-out frames' landmark "
        "residual "
        "(inter-ocular distances): a badly tracked frame, not a bad avatar.\n\n";
  if (!context.settings.empty()) md << "Settings: " << context.settings << "\n\n";
  md << "## Sources\n\n| source | origin | training frames | held-out frames | notes "
        "|\n|---|---|---|---|---|\n";
  for (const RealSourceInfo& s : context.sources) {
    std::string notes;
    for (const std::string& n : s.notes) notes += (notes.empty() ? "" : "; ") + n;
    md << "| " << s.name << " | " << s.origin << " | " << s.pool_train << " | " << s.test << " | " << notes
       << " |\n";
  }
  md << "\n## Results (means over the held-out frames)\n\n"
     << "| source | K | method | frames | face PSNR | face PSNR, still | face SSIM | head PSNR | head SSIM | "
        "LPIPS | "
        "id distance | real_expr_gain | track RMS | training |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const RealRunRecord* r : Ordered(runs, context)) {
    const RealMeans& m = r->metrics.means;
    char training[64];
    std::snprintf(training, sizeof training, "%lld steps, %.0f s", static_cast<long long>(r->train_steps),
                  r->train_seconds);
    md << "| " << r->source << " | " << r->k << " | " << r->method << " | " << m.count << " | "
       << Fmt(m.face_psnr, "%.2f") << " | " << Fmt(m.face_psnr_nearest, "%.2f") << " | "
       << Fmt(m.face_ssim, "%.3f") << " | " << Fmt(m.head_psnr, "%.2f") << " | " << Fmt(m.head_ssim, "%.3f")
       << " | " << Fmt(m.lpips, "%.3f") << " | " << Fmt(m.id_distance, "%.3f") << " | "
       << Fmt(m.real_expr_gain, "%.3f") << " | " << Fmt(m.track_rms_iod, "%.3f") << " | " << training
       << " |\n";
  }
  md << "\n## Per frame\n\n| run | frame | delta | face PSNR | face PSNR, still | real_expr_gain | track RMS "
        "|\n"
     << "|---|---|---|---|---|---|---|\n";
  for (const RealRunRecord* r : Ordered(runs, context))
    for (const RealFrameMetrics& f : r->metrics.frames)
      md << "| " << r->Name() << " | " << f.file_path << " | " << Fmt(f.delta, "%.3f") << " | "
         << Fmt(f.face_psnr, "%.2f") << " | " << Fmt(f.face_psnr_nearest, "%.2f") << " | "
         << Fmt(f.real_expr_gain, "%.3f") << " | " << Fmt(f.track_rms_iod, "%.3f") << " |\n";
  if (!images.empty()) {
    md << "\n## Pictures\n\n";
    for (const std::string& im : images) {
      if (im.rfind("worst_", 0) == 0)
        md << "Worst held-out frames by face PSNR (" << im
           << "; each row: photo, render at the tracked expression, render at the nearest training "
              "expression):\n\n";
      md << "![" << im << "](" << im << ")\n\n";
    }
  }
  return md.str();
}

std::string RealReportLatex(const std::vector<RealRunRecord>& runs, const RealReportContext& context) {
  std::ostringstream tex;
  tex << "% icef bench --real: means over the held-out real frames (needs \\usepackage{booktabs})\n"
      << "\\begin{table}\n\\centering\n\\small\n\\begin{tabular}{llrrrrrr}\n\\toprule\n"
      << "Source & Method & $K$ & Face PSNR & Still & Face SSIM & ID dist. & Expr. gain \\\\\n\\midrule\n";
  for (const RealRunRecord* r : Ordered(runs, context)) {
    const RealMeans& m = r->metrics.means;
    tex << LatexEscape(r->source) << " & " << LatexEscape(r->method) << " & " << r->k << " & "
        << Fmt(m.face_psnr, "%.2f") << " & " << Fmt(m.face_psnr_nearest, "%.2f") << " & "
        << Fmt(m.face_ssim, "%.3f") << " & " << Fmt(m.id_distance, "%.3f") << " & "
        << Fmt(m.real_expr_gain, "%.3f") << " \\\\\n";
  }
  tex << "\\bottomrule\n\\end{tabular}\n\\caption{Self-reenactment on real media: held-out frames rendered "
         "at their "
         "tracked camera and expression against the real photo. Still: the same camera at the nearest "
         "training "
         "expression. Expr.\\ gain: the share of the mouth/eye/brow error the tracked expression removes.}\n"
      << "\\label{tab:icef-bench-real}\n\\end{table}\n";
  return tex.str();
}

Result<Image> WorstFramesSheet(const RealRunRecord& run, int count) {
  std::vector<const RealFrameMetrics*> frames;
  for (const RealFrameMetrics& f : run.metrics.frames)
    if (f.face_psnr && !f.render_path.empty()) frames.push_back(&f);
  std::stable_sort(frames.begin(), frames.end(), [](const RealFrameMetrics* a, const RealFrameMetrics* b) {
    return *a->face_psnr < *b->face_psnr;
  });
  if (frames.size() > static_cast<size_t>(count)) frames.resize(count);
  std::vector<Image> rows;
  for (const RealFrameMetrics* f : frames) {
    ICEF_ASSIGN_OR_RETURN(const Image photo, ReadImage(run.dataset / f->file_path));
    ICEF_ASSIGN_OR_RETURN(const Image render, ReadImage(run.run_dir / f->render_path));
    ICEF_ASSIGN_OR_RETURN(const Image still, ReadImage(run.run_dir / f->nearest_path));
    rows.push_back(Row({CompositeOver(photo, Vec3f::Ones()), CompositeOver(render, Vec3f::Ones()),
                        CompositeOver(still, Vec3f::Ones())},
                       4));
  }
  if (rows.empty()) return Image();
  return Stack(rows, 4);
}

Status WriteRealReport(const fs::path& dir, const std::vector<RealRunRecord>& runs,
                       const RealReportContext& context) {
  const std::vector<const RealRunRecord*> ordered = Ordered(runs, context);
  std::string note;
  ICEF_ASSIGN_OR_RETURN(std::vector<std::string> images, WriteRealPlots(dir, ordered, &note));
  // Per source, the worst frames of its largest K's first method.
  std::map<std::string, const RealRunRecord*> largest;
  for (const RealRunRecord* r : ordered)
    if (!largest.count(r->source) || r->k > largest[r->source]->k) largest[r->source] = r;
  for (const auto& [source, run] : largest) {
    ICEF_ASSIGN_OR_RETURN(const Image sheet, WorstFramesSheet(*run, 3));
    if (sheet.width == 0) continue;
    const std::string name = "worst_" + run->Name() + ".png";
    ICEF_RETURN_IF_ERROR(WritePng(dir / name, sheet));
    images.push_back(name);
  }
  Json runs_json = Json::array();
  for (const RealRunRecord* r : ordered) runs_json.push_back(r->ToJson());
  Json sources = Json::array();
  for (const RealSourceInfo& s : context.sources)
    sources.push_back(Json{{"name", s.name},
                           {"origin", s.origin},
                           {"training_frames", s.pool_train},
                           {"held_out_frames", s.test},
                           {"notes", s.notes}});
  std::string md = RealReportMarkdown(runs, context, images);
  if (!note.empty()) md += "\n" + note + "\n";
  ICEF_RETURN_IF_ERROR(WriteFileAtomic(dir / "report.md", md));
  ICEF_RETURN_IF_ERROR(WriteFileAtomic(dir / "report.tex", RealReportLatex(runs, context)));
  return WriteFileAtomic(
      dir / "report.json",
      FormatJson(Json{{"settings", context.settings}, {"sources", sources}, {"runs", runs_json}}));
}

}  // namespace icef::eval
