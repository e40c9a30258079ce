#include "icef/core/enum_table.h"

#include <gtest/gtest.h>

namespace icef {
namespace {

enum class Colour { kRed, kGreen, kBlue };
constexpr std::array<EnumEntry<Colour>, 3> kColours = {
    {{Colour::kRed, "red"}, {Colour::kGreen, "green"}, {Colour::kBlue, "blue"}}};

TEST(EnumTableTest, NamesParsesAndListsFromOneTable) {
  EXPECT_STREQ(EnumName(kColours, Colour::kGreen), "green");
  for (const EnumEntry<Colour>& e : kColours) EXPECT_EQ(ParseEnum(kColours, e.name), e.value);
  EXPECT_FALSE(ParseEnum(kColours, "Green").has_value());
  EXPECT_FALSE(ParseEnum(kColours, "").has_value());
  EXPECT_EQ(EnumNames(kColours), "red, green, blue");
  EXPECT_EQ(EnumNames(kColours, " | "), "red | green | blue");
  static_assert(ParseEnum(kColours, "blue") == Colour::kBlue);
  EXPECT_STREQ(EnumName(kColours, static_cast<Colour>(7)), "?");
}

}  // namespace
}  // namespace icef
