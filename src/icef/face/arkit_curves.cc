#include "icef/face/arkit_curves.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

namespace icef::face {

namespace {

std::string Trimmed(std::string s) {
  const auto space = [](unsigned char c) { return std::isspace(c) != 0; };
  while (!s.empty() && space(s.back())) s.pop_back();
  size_t i = 0;
  while (i < s.size() && space(s[i])) ++i;
  return s.substr(i);
}

std::vector<std::string> Cells(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(Trimmed(cell));
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

bool SameName(const std::string& a, const char* b) {
  if (a.size() != std::char_traits<char>::length(b)) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i])))
      return false;
  return true;
}

// What each column is: the timecode, ignored (-1), or the expression indices it sets.
struct Columns {
  int timecode = -1;
  std::vector<std::vector<int>> targets;  // per column
};

Result<Columns> ParseHeader(const IctModel& model, const std::vector<std::string>& header,
                            const std::string& file, ArkitCurves* curves) {
  Columns c;
  std::vector<int> set_by(model.num_expressions(), -1);
  bool any = false;
  for (size_t i = 0; i < header.size(); ++i) {
    const std::string& name = header[i];
    c.targets.emplace_back();
    if (SameName(name, "Timecode")) {
      c.timecode = static_cast<int>(i);
      continue;
    }
    if (SameName(name, "BlendShapeCount")) continue;
    const std::vector<int> targets = model.ExpressionTargets(name);
    if (targets.empty()) {
      curves->ignored_columns.push_back(name);
      continue;
    }
    for (const int e : targets) {
      if (set_by[e] >= 0)
        return Status::Error(file + ":1: column '" + name + "' sets " + model.expression_names()[e] +
                             ", which column '" + header[set_by[e]] + "' sets already");
      set_by[e] = static_cast<int>(i);
    }
    c.targets.back() = targets;
    any = true;
  }
  if (!any)
    return Status::Error(file +
                         ":1: no blendshape column (expected Live Link Face's header: Timecode, "
                         "BlendShapeCount, EyeBlinkLeft, ..., JawOpen, ...)");
  return c;
}

}  // namespace

Result<ArkitCurves> ReadArkitCurves(const IctModel& model, const std::filesystem::path& csv) {
  const std::string file = csv.string();
  std::ifstream in(csv);
  if (!in) return Status::Error(file + ": cannot read the file");
  std::string line;
  if (!std::getline(in, line) || Trimmed(line).empty())
    return Status::Error(file + ":1: no header row (expected Timecode, BlendShapeCount, EyeBlinkLeft, ...)");
  if (line.size() >= 3 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line = line.substr(3);  // UTF-8 BOM
  ArkitCurves curves;
  const std::vector<std::string> header = Cells(line);
  ICEF_ASSIGN_OR_RETURN(const Columns columns, ParseHeader(model, header, file, &curves));
  std::vector<bool> covered(model.num_expressions(), false);
  for (const std::vector<int>& t : columns.targets)
    for (const int e : t) covered[e] = true;
  for (const std::string& name : model.ArkitNames()) {
    const std::vector<int> t = model.ExpressionTargets(name);
    if (std::none_of(t.begin(), t.end(), [&](int e) { return covered[e]; }))
      curves.missing_columns.push_back(name);
  }
  for (int number = 2; std::getline(in, line); ++number) {
    if (Trimmed(line).empty()) continue;
    const std::vector<std::string> cells = Cells(line);
    const std::string where = file + ":" + std::to_string(number);
    if (cells.size() != header.size())
      return Status::Error(where + ": " + std::to_string(cells.size()) + " cells, the header has " +
                           std::to_string(header.size()));
    std::vector<float> w(model.num_expressions(), 0.f);
    for (size_t i = 0; i < cells.size(); ++i) {
      if (columns.targets[i].empty()) continue;
      float v = 0;
      const char* begin = cells[i].data();
      const char* end = begin + cells[i].size();
      const auto [ptr, ec] = std::from_chars(begin, end, v);
      if (ec != std::errc() || ptr != end || !std::isfinite(v))
        return Status::Error(where + ": " + header[i] + ": '" + cells[i] + "' is not a finite number");
      for (const int e : columns.targets[i]) w[e] = v;
    }
    curves.timecodes.push_back(columns.timecode >= 0 ? cells[columns.timecode] : std::string());
    curves.weights.push_back(std::move(w));
  }
  if (curves.weights.empty()) return Status::Error(file + ": no frames after the header");
  return curves;
}

std::string ArkitCurves::ToString() const {
  std::ostringstream os;
  os << "ArkitCurves(" << weights.size() << " frames";
  if (!timecodes.empty() && !timecodes.front().empty())
    os << ", " << timecodes.front() << " to " << timecodes.back();
  if (!ignored_columns.empty()) {
    os << ", ignored:";
    for (const std::string& c : ignored_columns) os << " " << c;
  }
  if (!missing_columns.empty()) {
    os << ", missing (held at 0):";
    for (const std::string& c : missing_columns) os << " " << c;
  }
  os << ")";
  return os.str();
}

}  // namespace icef::face
