// One table per enum: each value beside its name, written once. The name of a value, the value of
// a name and the list of valid names (for error messages) all come from the table.
//
//   constexpr std::array<EnumEntry<Tier>, 4> kTierNames = {{{Tier::kObserved, "observed"}, ...}};
//   EnumName(kTierNames, Tier::kNear) == "near"; ParseEnum(kTierNames, "far") == Tier::kFar.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace icef {

template <class E>
struct EnumEntry {
  E value;
  const char* name;
};

// The name of `value`; "?" for a value the table lacks (a broken table).
template <class E, size_t N>
constexpr const char* EnumName(const std::array<EnumEntry<E>, N>& table, E value) {
  for (const EnumEntry<E>& e : table)
    if (e.value == value) return e.name;
  return "?";
}

// The value named `name` (exact match); nullopt when none is.
template <class E, size_t N>
constexpr std::optional<E> ParseEnum(const std::array<EnumEntry<E>, N>& table, std::string_view name) {
  for (const EnumEntry<E>& e : table)
    if (name == e.name) return e.value;
  return std::nullopt;
}

// Every name in table order, joined by `separator` ("observed, near, moderate, far").
template <class E, size_t N>
std::string EnumNames(const std::array<EnumEntry<E>, N>& table, const char* separator = ", ") {
  std::string out;
  for (const EnumEntry<E>& e : table) out += (out.empty() ? "" : separator) + std::string(e.name);
  return out;
}

}  // namespace icef
