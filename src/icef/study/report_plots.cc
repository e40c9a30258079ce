#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "icef/io/atomic_file.h"
#include "icef/study/report.h"

namespace fs = std::filesystem;

namespace icef::eval {

namespace {

std::string ShellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// The gnuplot commands drawing one metric: one panel per K, one line per method.
std::string PlotCommands(const Aggregate& a, Metric m, const std::string& dat) {
  std::ostringstream s;
  s << "set multiplot layout 1," << a.ks.size() << " title \"" << MetricName(m)
    << " against delta (mean +- std over " << a.identities.size() << " identities)\"\n";
  s << "set xlabel \"delta (distance to the nearest training expression)\"\n";
  s << "set ylabel \"" << MetricLabel(m)
    << "\"\nset grid\nset key below horizontal box\nset offsets 0.05, 0.05, 0, 0\n";
  for (size_t ki = 0; ki < a.ks.size(); ++ki) {
    s << "set title \"K = " << a.ks[ki] << "\"\nplot ";
    for (size_t mi = 0; mi < a.methods.size(); ++mi) {
      s << (mi ? ", " : "") << "'" << dat << "' index " << ki * a.methods.size() + mi
        << " using 1:2:3 with yerrorlines lw 2 pt 7 title \"" << a.methods[mi] << "\"";
    }
    s << "\n";
  }
  s << "unset multiplot\n";
  return s.str();
}

}  // namespace

bool HaveGnuplot() { return std::system("command -v gnuplot >/dev/null 2>&1") == 0; }

Status RunGnuplot(const fs::path& plot_dir, const std::string& name) {
  const std::string cmd = "cd " + ShellQuote(plot_dir.string()) + " && gnuplot " + ShellQuote(name + ".gp") +
                          " >" + ShellQuote(name + ".log") + " 2>&1";
  if (std::system(cmd.c_str()) != 0)
    return Status::Error((plot_dir / (name + ".gp")).string() + ": gnuplot failed (see " +
                         (plot_dir / (name + ".log")).string() + ")");
  std::error_code ec;
  fs::remove(plot_dir / (name + ".log"), ec);
  return Status::Ok();
}

Result<std::vector<std::string>> WritePlots(const fs::path& dir, const Aggregate& a, std::string* note) {
  std::vector<std::string> pngs;
  if (a.ks.empty() || a.methods.empty()) return pngs;
  const fs::path plot_dir = dir / "plots";
  std::error_code ec;
  fs::create_directories(plot_dir, ec);
  if (ec) return Status::Error(plot_dir.string() + ": cannot create directory: " + ec.message());
  const bool have_gnuplot = HaveGnuplot();
  const int width = 380 * static_cast<int>(a.ks.size()) + 80;
  for (Metric m : AllMetrics()) {
    bool any = false;
    std::ostringstream dat;
    dat.precision(9);
    dat << "# " << MetricName(m)
        << ": blocks per (K, method) in order; columns: mean delta, mean, std, min, max, runs\n";
    for (int k : a.ks)
      for (const std::string& method : a.methods) {
        dat << "# K=" << k << " method=" << method << "\n";
        bool rows = false;
        for (Tier tier : AllTiers()) {
          const AggregateCell* c = a.Find(k, method, tier);
          if (!c || !c->Get(m) || !c->delta) continue;
          const Spread v = *c->Get(m);
          dat << c->delta->mean << " " << v.mean << " " << v.std << " " << v.min << " " << v.max << " " << v.n
              << "\n";
          rows = any = true;
        }
        if (!rows) dat << "NaN NaN NaN NaN NaN 0\n";
        dat << "\n\n";
      }
    if (!any) continue;
    const std::string name = MetricName(m);
    ICEF_RETURN_IF_ERROR(WriteFileAtomic(plot_dir / (name + ".dat"), dat.str()));
    const std::string commands = PlotCommands(a, m, name + ".dat");
    std::ostringstream gp;
    // The PDF (vector, for a paper's \includegraphics): the PNG's layout at 150 px per inch (8.1 in wide
    // for three K), its type at 7 pt.
    char pdf_size[48];
    std::snprintf(pdf_size, sizeof pdf_size, "%.2fin,%.2fin", width / 150.0, 480 / 150.0);
    gp << "# gnuplot " << name << ".gp (run in this directory) draws " << name << ".png, " << name
       << ".svg and " << name << ".pdf\n"
       << "set terminal pngcairo noenhanced size " << width << ",480 font \"sans,9\"\nset output \"" << name
       << ".png\"\n"
       << commands << "set terminal svg noenhanced size " << width << ",480 font \"sans,9\"\nset output \""
       << name << ".svg\"\n"
       << commands << "set terminal pdfcairo noenhanced size " << pdf_size
       << " font \"sans,7\"\nset output \"" << name << ".pdf\"\n"
       << commands << "unset output\n";
    ICEF_RETURN_IF_ERROR(WriteFileAtomic(plot_dir / (name + ".gp"), gp.str()));
    if (!have_gnuplot) continue;
    ICEF_RETURN_IF_ERROR(RunGnuplot(plot_dir, name));
    pngs.push_back("plots/" + name + ".png");
  }
  if (!have_gnuplot && note)
    *note =
        "Plots not drawn: gnuplot is not installed (apt-get install gnuplot-nox); run `gnuplot X.gp` in "
        "plots/.";
  return pngs;
}

}  // namespace icef::eval
