// RunEval's errors: a missing model, an invalid option, a refused override; each before any
// output is written.
#include "icef/app/eval_app.h"

#include <gtest/gtest.h>

#include <limits>
#include <sstream>

#include "icef/app/app_test_util.h"

namespace icef {
namespace {

namespace fs = std::filesystem;

EvalAppOptions TinyEval(const std::string& name) {
  const fs::path dir = testing::MakeTempDir(name);
  testing::WriteTinyDataset(dir / "data");
  EvalAppOptions o;
  o.model = dir / "model";
  o.dataset = dir / "data";
  o.out = dir / "eval";
  return o;
}

TEST(EvalApp, MissingModelIsAClearError) {
  const EvalAppOptions o = TinyEval("eval_app_missing");
  std::ostringstream out, err;
  const Status s = RunEval(o, Executor(1), out, err).status();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find(o.model.string() + ": no checkpoint here"), std::string::npos) << s.message();
  EXPECT_FALSE(fs::exists(o.out / "metrics.json"));
}

TEST(EvalApp, InvalidExpressionScaleNamesTheOption) {
  EvalAppOptions o = TinyEval("eval_app_scale");
  o.expression_scale = std::numeric_limits<double>::infinity();
  EXPECT_NE(o.Validate().message().find("--expression-scale: expression_scale: must be a finite number"),
            std::string::npos)
      << o.Validate().message();
  std::ostringstream out, err;
  EXPECT_FALSE(RunEval(o, Executor(1), out, err).ok());
  o.expression_scale = 0;
  EXPECT_TRUE(o.Validate().ok());
}

TEST(EvalApp, RefusedOverrideNamesTheKey) {
  EvalAppOptions o = TinyEval("eval_app_override");
  testing_app::WriteTinyModelDir(o.model);
  o.overrides = {"model.deformation.hidden=[8,8]"};
  std::ostringstream out, err;
  const Status s = RunEval(o, Executor(1), out, err).status();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("model.deformation.hidden cannot be changed on a trained model"),
            std::string::npos)
      << s.message();
  EXPECT_FALSE(fs::exists(o.out / "metrics.json"));
}

}  // namespace
}  // namespace icef
