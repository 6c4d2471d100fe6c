#pragma once
// Reading the JSON files the tool takes as input (problems, models, scenarios, constraints, plans).
// Every reader is strict: a key it does not know is an error that names the key, where it is and the keys
// that are allowed, so a misspelt option never falls back to a default in silence.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace hw {

// Throws InputError "<where>: unknown key '<key>'; allowed keys: ..." for the first key of the object `j`
// outside `allowed`, and "<where>: expected a JSON object" when `j` is not an object.
void CheckKeys(const nlohmann::json& j, const std::vector<std::string_view>& allowed, const std::string& where);

// The parsed contents of a JSON file; a missing file, a directory or invalid JSON is an InputError that
// names the file and says what it should be (`what`, e.g. "model file").
nlohmann::json ReadJsonFile(const std::string& path, const std::string& what);
// The same for JSON text read elsewhere; `source` names it in the message.
nlohmann::json ParseJsonText(const std::string& text, const std::string& source, const std::string& what);
// A file the tool wrote itself and reads back (a run cache's finished job, a study's run): nothing when it is
// missing or damaged, so that the caller computes it again rather than trusting it.
std::optional<nlohmann::json> ReadStoredJson(const std::string& path);

}  // namespace hw
