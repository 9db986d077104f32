#include "core/json_text.h"

#include <set>
#include <vector>

#include "core/error.h"
#include "core/error_text.h"
#include "core/text_parsing.h"

namespace mmh {
namespace {

// One open object or array while parsing: its keys so far (objects) and the key being read.
struct Level {
  bool object = false;
  std::set<std::string> keys;
  std::string key;
  std::size_t index = 0;
};

std::string PathOf(const std::vector<Level>& levels) {
  std::string path;
  for (const Level& level : levels) {
    if (level.object) {
      path += (path.empty() ? "" : ".") + level.key;
    } else {
      path += "[" + std::to_string(level.index) + "]";
    }
  }
  return path;
}

}  // namespace

nlohmann::json ParseJsonText(std::string_view text, const std::string& source) {
  using Event = nlohmann::json::parse_event_t;
  std::vector<Level> levels;
  // After a value inside an array, the next one has the next index.
  auto next_in_array = [&] {
    if (!levels.empty() && !levels.back().object) ++levels.back().index;
  };
  auto callback = [&](int, Event event, nlohmann::json& parsed) {
    switch (event) {
      case Event::object_start:
        levels.push_back(Level{true, {}, {}, 0});
        break;
      case Event::array_start:
        levels.push_back(Level{false, {}, {}, 0});
        break;
      case Event::key: {
        Level& level = levels.back();
        level.key = parsed.get<std::string>();
        if (!level.keys.insert(level.key).second) {
          ThrowBadValue(source + ": key " + Quote(PathOf(levels), 80),
                        "a key that appears twice in one object",
                        "each key once (JSON parsers disagree on which one wins)");
        }
        break;
      }
      case Event::object_end:
      case Event::array_end:
        levels.pop_back();
        next_in_array();
        break;
      case Event::value:
        next_in_array();
        break;
    }
    return true;
  };
  try {
    return nlohmann::json::parse(text.begin(), text.end(), callback);
  } catch (const nlohmann::json::out_of_range& e) {
    ThrowBadValue(source, "a number out of range (" + std::string(e.what()) + ")",
                  "a number a double can hold");
  } catch (const nlohmann::json::parse_error& e) {
    // Byte offset -> line and column.
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i + 1 < e.byte && i < text.size(); ++i) {
      if (text[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    // nlohmann's message quotes the last token read whole: escape and shorten it.
    throw InputError(source + ":" + std::to_string(line) + ":" + std::to_string(column) +
                     ": invalid JSON (" + EscapeForMessage(e.what(), 200) + ")");
  }
}

nlohmann::json ReadJsonFile(const std::filesystem::path& path) {
  return ParseJsonText(ReadTextFile(path, kMaxJsonFileBytes), path.string());
}

}  // namespace mmh
