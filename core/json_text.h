// Parsing JSON text from outside (configs, --set values, camera.json): strict where nlohmann's
// parser is lenient. A key repeated in one object is an error (the parser keeps the last one, so a
// repeated section would silently drop the first), and syntax errors name the line and column.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace mmh {

// Largest JSON file (config, camera.json) read [bytes]: the cap refuses /dev/zero or a wrong file
// before it fills the memory.
inline constexpr std::size_t kMaxJsonFileBytes = std::size_t{16} << 20;

// Parses `text`; throws InputError naming `source` (a file or "--set key=value") and, for a syntax
// error, the line and column, or for a repeated key its path (e.g. 'montage.dtw.lambda').
nlohmann::json ParseJsonText(std::string_view text, const std::string& source);

// Reads `path` (ReadTextFile's checks: unreadable, binary, UTF-16, larger than kMaxJsonFileBytes)
// and parses it with ParseJsonText; every error names the file.
nlohmann::json ReadJsonFile(const std::filesystem::path& path);

}  // namespace mmh
