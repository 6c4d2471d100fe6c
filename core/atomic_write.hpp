#pragma once
// Results are written atomically: to path + ".tmp", then renamed, so a killed run never leaves a half-written file.
#include <string>

namespace hw {

// Throws std::runtime_error naming the path when the file cannot be written (the temporary file is removed).
void write_text_atomic(const std::string& path, const std::string& text);

}  // namespace hw
