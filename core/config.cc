#include "core/config.h"

#include "core/error.h"
#include "core/error_text.h"
#include "core/json_text.h"
#include "core/text_parsing.h"

namespace mmh {

Config Config::Load(const std::filesystem::path& path) {
  const std::string text = ReadTextFile(path, kMaxJsonFileBytes);
  Config config;
  config.file_ = path.string();
  config.root_ = ParseJsonText(text, path.string());
  if (!config.root_.is_object()) {
    ThrowBadValue(path.string(), "a JSON " + std::string(config.root_.type_name()),
                  "a JSON object with one key per section, e.g. {\"montage\": {...}}");
  }
  return config;
}

void Config::Set(const std::string& assignment) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) {
    ThrowBadValue("--set " + assignment, "no 'key.path=value'", "key.path=value");
  }
  const std::string key_path = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  // Keys and text values are kept as JSON strings, which must be UTF-8: anything else would
  // fail later, when the config is written or quoted (a fuzzer finding: an uncaught type_error).
  for (const std::string& part : {key_path, text}) {
    try {
      (void)nlohmann::json(part).dump();
    } catch (const nlohmann::json::type_error&) {
      ThrowBadValue("--set " + EscapeForMessage(assignment, 80), Quote(part),
                    "a key and value in UTF-8");
    }
  }
  // Not JSON: a bare string (--set montage.blend.weight=smoothstep).
  const nlohmann::json value =
      nlohmann::json::accept(text)
          ? ParseJsonText(text, "--set " + EscapeForMessage(assignment, 80))
          : nlohmann::json(text);
  nlohmann::json* node = &root_;
  std::size_t start = 0;
  while (true) {
    const std::size_t dot = key_path.find('.', start);
    const std::string name = key_path.substr(start, dot == std::string::npos ? dot : dot - start);
    if (name.empty()) ThrowBadValue("--set " + assignment, "an empty key", "key.path=value");
    if (!node->is_object()) {
      ThrowBadValue("--set " + assignment, "a key inside a non-object value", "a key of an object");
    }
    if (dot == std::string::npos) {
      (*node)[name] = value;
      break;
    }
    node = &(*node)[name];
    if (node->is_null()) *node = nlohmann::json::object();
    start = dot + 1;
  }
  overrides_[key_path] = assignment;
}

namespace {

// A --set of `key` wrote (part of) the value at `key_path`: the same key, one below it or one
// above it.
bool SetReaches(const std::string& key, const std::string& key_path) {
  return key == key_path || key.rfind(key_path + ".", 0) == 0 || key_path.rfind(key + ".", 0) == 0;
}

}  // namespace

ConfigSource Config::SourceOf(const std::string& key_path) const {
  // The most specific --set at or below this key wins; otherwise the file.
  std::string sets;
  for (const auto& [key, assignment] : overrides_) {
    if (SetReaches(key, key_path)) {
      sets += (sets.empty() ? "" : ", ") + ("--set " + assignment);
    }
  }
  std::string name = file_.empty() ? "config" : file_;
  if (!sets.empty()) name = file_.empty() ? sets : name + " with " + sets;
  return ConfigSource{name};
}

std::filesystem::path Config::FolderOf(const std::string& key_path) const {
  for (const auto& [key, assignment] : overrides_) {
    if (SetReaches(key, key_path)) return {};
  }
  if (file_.empty()) return {};
  return std::filesystem::path(file_).parent_path();
}

void Config::RequireOnlySections(const std::vector<std::string>& sections) const {
  for (auto it = root_.begin(); it != root_.end(); ++it) {
    bool known = false;
    for (const auto& s : sections) known = known || s == it.key();
    if (!known) {
      const std::string suggestion = options_internal::SuggestName(it.key(), sections);
      throw InputError(SourceOf(it.key()).name + ": section '" + it.key() + "' is unknown" +
                       (suggestion.empty() ? "" : " (did you mean '" + suggestion + "'?)") +
                       "; this command reads: " + options_internal::JoinNames(sections));
    }
  }
}

}  // namespace mmh
