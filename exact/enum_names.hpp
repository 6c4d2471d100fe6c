#pragma once
// Options named on command lines and in JSON: the enum value whose ToString is the text (found by ADL).
#include <initializer_list>
#include <string>

namespace hw::exact {

template <class Enum>
bool ParseByName(const std::string& text, std::initializer_list<Enum> values, Enum* out) {
  for (Enum v : values)
    if (text == ToString(v)) {
      *out = v;
      return true;
    }
  return false;
}

}  // namespace hw::exact
