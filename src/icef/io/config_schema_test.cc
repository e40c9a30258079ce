#include "icef/io/config_schema.h"

#include <gtest/gtest.h>

namespace icef {
namespace {

struct Example {
  int steps = 10;
  double lr = 0.5;
  float scale = 2.f;
  bool flag = false;
  std::string name = "a";
  std::vector<int> widths = {1, 2};
  int64_t big = 7;
  void Bind(ConfigSchema& s) {
    s.Int("steps", &steps, "steps");
    s.Number("lr", &lr, "learning rate");
    s.Float("scale", &scale, "scale");
    s.Bool("flag", &flag, "flag");
    s.String("name", &name, "name");
    s.IntArray("widths", &widths, "widths");
    s.Int64("big", &big, "big");
  }
};

Result<Example> Parse(const std::string& text) {
  ICEF_ASSIGN_OR_RETURN(Json j, ParseJson(text, "cfg.json"));
  ICEF_ASSIGN_OR_RETURN(JsonObjectView v, JsonObjectView::Make(j, "cfg.json", ""));
  Example e;
  ICEF_RETURN_IF_ERROR(ReadConfig(v, &e));
  return e;
}

TEST(ConfigSchemaTest, ReadsKnownKeysAndKeepsDefaults) {
  auto e = Parse(R"({"steps": 5, "widths": [3, 4, 5], "flag": true})");
  ASSERT_TRUE(e.ok()) << e.status().message();
  EXPECT_EQ(e->steps, 5);
  EXPECT_EQ(e->widths, (std::vector<int>{3, 4, 5}));
  EXPECT_TRUE(e->flag);
  EXPECT_EQ(e->lr, 0.5);
  EXPECT_EQ(e->name, "a");
}

TEST(ConfigSchemaTest, UnknownKeyIsAnErrorListingValidKeys) {
  auto e = Parse(R"({"stpes": 5})");
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.status().message().find("cfg.json"), std::string::npos);
  EXPECT_NE(e.status().message().find("stpes"), std::string::npos);
  EXPECT_NE(e.status().message().find("valid keys: steps, lr"), std::string::npos);
}

TEST(ConfigSchemaTest, WrongTypesAndValuesNameTheKey) {
  for (const char* bad : {R"({"steps": "x"})", R"({"steps": 1.5})", R"({"widths": [1, 2.5]})",
                          R"({"flag": 1})", R"({"lr": NaN})", R"({"scale": 1e300})"}) {
    auto e = Parse(bad);
    ASSERT_FALSE(e.ok()) << bad;
  }
}

TEST(ConfigSchemaTest, WriteRoundTripsAndDocuments) {
  Example e;
  e.steps = 42;
  e.scale = 0.1f;
  const Json j = WriteConfig(e);
  EXPECT_EQ(j["steps"], 42);
  auto back = Parse(j.dump());
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->steps, 42);
  EXPECT_EQ(back->scale, 0.1f);
  ConfigSchema s;
  Example d;
  d.Bind(s);
  EXPECT_NE(s.MarkdownRows().find("| `lr` | `0.5` | learning rate |"), std::string::npos);
}

struct Inner {
  int width = 4;
  double rate = 0.25;
};
struct Outer {
  int steps = 1;
  Inner inner;
  void Bind(ConfigSchema& s) {
    s.Int("steps", &steps, "steps");
    s.Block("inner", [this](ConfigSchema& b) {
      b.Int("width", &inner.width, "inner width");
      b.Number("rate", &inner.rate, "inner rate");
    });
    s.Renamed("inner_width", "inner.width");
  }
};

Result<Outer> ParseOuter(const std::string& text,
                         ConfigSchema::OldKeys old_keys = ConfigSchema::OldKeys::kReject) {
  ICEF_ASSIGN_OR_RETURN(Json j, ParseJson(text, "cfg.json"));
  ICEF_ASSIGN_OR_RETURN(JsonObjectView v, JsonObjectView::Make(j, "cfg.json", ""));
  Outer o;
  ICEF_RETURN_IF_ERROR(ReadConfig(v, &o, old_keys));
  return o;
}

TEST(ConfigSchemaTest, BlocksReadWriteAndDocumentTheirKeysAsPaths) {
  auto o = ParseOuter(R"({"inner": {"width": 9}})");
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_EQ(o->inner.width, 9);
  EXPECT_EQ(o->inner.rate, 0.25);  // absent inside the block: kept
  const Json j = WriteConfig(*o);
  EXPECT_EQ(j["inner"]["width"], 9);
  EXPECT_EQ(j["inner"]["rate"], 0.25);
  ConfigSchema s;
  Outer d;
  d.Bind(s);
  EXPECT_EQ(s.Keys(), (std::vector<std::string>{"steps", "inner.width", "inner.rate"}));
  EXPECT_NE(s.MarkdownRows().find("| `inner.width` | `4` | inner width |\n"), std::string::npos)
      << s.MarkdownRows();
  // Errors inside a block name the block's path.
  auto bad = ParseOuter(R"({"inner": {"widht": 9}})");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("cfg.json: inner.widht: unknown key (valid keys: width, rate)"),
            std::string::npos)
      << bad.status().message();
  EXPECT_FALSE(ParseOuter(R"({"inner": 3})").ok());
  EXPECT_FALSE(ParseOuter(R"({"inner": {"width": "x"}})").ok());
}

TEST(ConfigSchemaTest, RenamedKeysAreReadOnlyWhenAskedAndNeverTwice) {
  auto rejected = ParseOuter(R"({"inner_width": 7})");
  ASSERT_FALSE(rejected.ok());
  EXPECT_NE(rejected.status().message().find("inner_width: renamed to inner.width"), std::string::npos)
      << rejected.status().message();
  auto read = ParseOuter(R"({"inner_width": 7, "inner": {"rate": 0.5}})", ConfigSchema::OldKeys::kRead);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read->inner.width, 7);
  EXPECT_EQ(read->inner.rate, 0.5);
  auto twice = ParseOuter(R"({"inner_width": 7, "inner": {"width": 8}})", ConfigSchema::OldKeys::kRead);
  ASSERT_FALSE(twice.ok());
  EXPECT_NE(twice.status().message().find("given twice"), std::string::npos) << twice.status().message();
  ConfigSchema schema;
  Outer probe;
  probe.Bind(schema);
  EXPECT_EQ(schema.RenamedTo("inner_width"), "inner.width");
  EXPECT_EQ(schema.RenamedTo("steps"), "");
  // Old names are not written.
  EXPECT_FALSE(WriteConfig(*read).contains("inner_width"));
}

}  // namespace
}  // namespace icef
