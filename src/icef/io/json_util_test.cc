#include "icef/io/json_util.h"

#include <gtest/gtest.h>

#include <cmath>

namespace icef {
namespace {

Json Parse(const std::string& text) { return ParseJson(text, "f.json").value(); }

TEST(JsonUtil, TypedGettersReadValues) {
  const Json doc = Parse(R"({"n": 2.5, "i": 7, "b": true, "s": "x", "a": [1, 2, 3],
                             "m": [[1, 2], [3, 4]], "names": ["u", "v"], "flags": [true, false],
                             "frames": [{"k": 1}, {"k": 2}]})");
  const JsonObjectView root = JsonObjectView::Make(doc, "f.json", "").value();
  EXPECT_EQ(root.Number("n").value(), 2.5);
  EXPECT_EQ(root.Int("i").value(), 7);
  EXPECT_TRUE(root.Bool("b").value());
  EXPECT_EQ(root.String("s").value(), "x");
  EXPECT_EQ(root.NumberArray("a", 3).value(), (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(root.NumberMatrix("m", 2, 2).value()[1][0], 3.0);
  EXPECT_EQ(root.StringArray("names", 2).value()[1], "v");
  EXPECT_EQ(root.BoolArray("flags").value(), (std::vector<bool>{true, false}));
  const auto frames = root.ObjectArray("frames").value();
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[1].path(), "frames[1]");
  EXPECT_EQ(frames[1].Int("k").value(), 2);
}

TEST(JsonUtil, ErrorsNameFileAndField) {
  const Json doc = Parse(R"({"frames": [{"expression": [1, 2], "tier": 3, "x": "1"}]})");
  const auto frame = JsonObjectView::Make(doc, "f.json", "").value().ObjectArray("frames").value()[0];
  EXPECT_EQ(frame.NumberArray("expression", 12).status().message(),
            "f.json: frames[0].expression: expected an array of 12 numbers, got 2 values");
  EXPECT_EQ(frame.String("tier").status().message(),
            "f.json: frames[0].tier: expected a string, got a number");
  EXPECT_EQ(frame.Number("x").status().message(), "f.json: frames[0].x: expected a number, got a string");
  EXPECT_EQ(frame.Number("missing").status().message(), "f.json: frames[0].missing: missing required field");
  EXPECT_FALSE(frame.Int("expression").ok());
  EXPECT_FALSE(frame.NumberMatrix("expression", 2, 2).ok());
}

TEST(JsonUtil, IntRejectsFractions) {
  const Json doc = Parse(R"({"w": 12.5, "h": 1e12})");
  const auto root = JsonObjectView::Make(doc, "f.json", "").value();
  EXPECT_NE(root.Int("w").status().message().find("expected an integer"), std::string::npos);
  EXPECT_FALSE(root.Int("h").ok());
}

TEST(JsonUtil, PythonNonFiniteLiteralsAreReportedAtTheirField) {
  const Json doc = Parse(R"({"m": [[1, NaN], [0, 1]], "s": "NaN stays a string", "v": -Infinity})");
  const auto root = JsonObjectView::Make(doc, "f.json", "").value();
  EXPECT_EQ(root.NumberMatrix("m", 2, 2).status().message(), "f.json: m: non-finite value NaN at [0][1]");
  EXPECT_EQ(root.String("s").value(), "NaN stays a string");
  EXPECT_EQ(root.Number("v").status().message(), "f.json: v: expected a finite number, got -Infinity");
}

TEST(JsonUtil, ParseErrorNamesTheFile) {
  const auto result = ParseJson("{\"a\": [1, 2,}", "bad.json");
  ASSERT_FALSE(result.ok());
  EXPECT_TRUE(result.status().message().starts_with("bad.json: invalid JSON: "));
  EXPECT_EQ(result.status().message().find('\n'), std::string::npos);
  EXPECT_FALSE(ParseJson("[1e999]", "big.json").ok());
}

TEST(JsonUtil, MakeRejectsNonObjects) {
  const Json doc = Parse("[1, 2]");
  EXPECT_EQ(JsonObjectView::Make(doc, "f.json", "").status().message(),
            "f.json: expected an object, got an array of 2");
}

TEST(JsonUtil, UnknownKeysListsExtras) {
  const Json doc = Parse(R"({"a": 1, "zz": 2, "b": 3})");
  const auto root = JsonObjectView::Make(doc, "f.json", "").value();
  EXPECT_EQ(root.UnknownKeys({"a", "b"}), std::vector<std::string>{"zz"});
}

TEST(JsonUtil, JsonFloatRoundTripsShortest) {
  EXPECT_EQ(JsonFloat(0.1f).dump(), "0.1");
  for (float v : {0.1f, 1.f / 3.f, 123456.789f, -2.5e-8f, 3.4e38f}) {
    const Json parsed = Json::parse(JsonFloat(v).dump());
    EXPECT_EQ(static_cast<float>(parsed.get<double>()), v);
  }
}

TEST(JsonUtil, FormatJsonKeepsScalarArraysOnOneLineAndReparses) {
  const Json doc = Parse(R"({"m": [[1, 0], [0, 1]], "e": [0.5, 1], "o": {"s": "x"}, "empty": []})");
  const std::string text = FormatJson(doc);
  EXPECT_NE(text.find("\"e\": [0.5, 1]"), std::string::npos) << text;
  EXPECT_NE(text.find("[1, 0],"), std::string::npos) << text;
  EXPECT_EQ(Json::parse(text), doc);
}

TEST(JsonUtil, Int64AndUint64AreExactAndRangeChecked) {
  const Json doc = Parse(R"({"step": 120, "neg": -1, "half": 1.5, "big": 1e300, "whole": 3.0,
                             "hash": 18446744073709551615, "s": "7"})");
  const JsonObjectView t = JsonObjectView::Make(doc, "ckpt", "trainer").value();
  EXPECT_EQ(t.Int64("step", 0, 1000).value(), 120);
  EXPECT_EQ(t.Int64("whole", 0, 1000).value(), 3);
  EXPECT_EQ(t.Int64("neg", 0, 1000).status().message(),
            "ckpt: trainer.neg: expected an integer in [0, 1000], got -1");
  EXPECT_EQ(t.Int64("half", 0, 1000).status().message(),
            "ckpt: trainer.half: expected an integer in [0, 1000], got 1.5");
  EXPECT_FALSE(t.Int64("big", 0, int64_t(1) << 53).ok());
  EXPECT_FALSE(t.Int64("hash", 0, int64_t(1) << 53).ok());
  EXPECT_FALSE(t.Int64("s", 0, 10).ok());
  EXPECT_EQ(t.Uint64("hash").value(), 18446744073709551615ULL);
  EXPECT_EQ(t.Uint64("step").value(), 120u);
  EXPECT_EQ(t.Uint64("neg").status().message(), "ckpt: trainer.neg: expected a non-negative integer, got -1");
  EXPECT_FALSE(t.Uint64("whole").ok());
}

TEST(JsonUtil, DifferencesNameNestedKeys) {
  const Json a = Parse(R"({"model": {"method": "icef", "hidden": [16]}, "train": {"steps": 10, "lr": 0.1}})");
  const Json b = Parse(R"({"model": {"method": "warp", "hidden": [16]}, "train": {"steps": 20, "seed": 1}})");
  EXPECT_EQ(JsonDifferences(a, a), std::vector<std::string>{});
  EXPECT_EQ(JsonDifferences(a, b),
            (std::vector<std::string>{"model.method", "train.steps", "train.lr", "train.seed"}));
}

}  // namespace
}  // namespace icef
