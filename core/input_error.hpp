#pragma once
// Bad input: a file, an option or a value a person gave. The message names where (file, line, option), what is
// wrong and what would be right; front ends print it and exit non-zero.
#include <stdexcept>

namespace hw {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace hw
