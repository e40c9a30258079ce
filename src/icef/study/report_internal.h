// What the bench report's parts share (study/aggregate.cc, verdict.cc, identity_rows.cc and the
// report writers): method order, number formatting, the per-identity rows. Not for use outside study/.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "icef/study/aggregate.h"

namespace icef::eval {

// Methods in AllMethods() order, then others by name.
bool MethodLess(const std::string& a, const std::string& b);
// "mean ± std [min, max]" of a spread in `format`, "-" when absent.
std::string Pm(const std::optional<Spread>& s, const char* format);
// A value in `format`, "-" when absent.
std::string Opt(const std::optional<double>& v, const char* format);
// The baselines icef is judged against (warp, nerface) and the methods the verdict speaks for.
const std::vector<std::string>& Baselines();
const std::vector<std::string>& PrimaryMethods();

// One run's row of the per-identity table.
struct IdentityRow {
  const RunRecord* run = nullptr;
  std::optional<double> train_face_psnr, observed_psnr, far_psnr, observed_region_psnr,
      observed_id_distance_gt, far_expr_gain, train_face_psnr_min, train_face_detail;
};

// The identity whose runs have the lowest mean of one value, and its run with the lowest value.
struct WorstIdentity {
  uint64_t seed = 0;
  double mean = 0;
  int runs = 0;  // its runs with a value
  const RunRecord* worst_run = nullptr;
  double worst_value = 0;
  Json ToJson() const {
    return Json{{"identity_seed", seed},
                {"mean", mean},
                {"runs", runs},
                {"worst_run", worst_run->id.Name()},
                {"worst_value", worst_value}};
  }
};

// The rows of every run, by identity, K and method.
std::vector<IdentityRow> IdentityRows(const std::vector<RunRecord>& runs);
std::string WorstIdentityLine(const std::optional<WorstIdentity>& w, const std::string& what,
                              const std::map<std::string, std::string>& run_sheets);
// The worst identities of a per-identity report: by training-view face PSNR, then by observed PSNR.
std::array<std::optional<WorstIdentity>, 2> WorstIdentities(const std::vector<IdentityRow>& rows);

}  // namespace icef::eval
