// A run's configuration: a JSON file (optional) plus `--set key.path=value` overrides, read into
// Options structs section by section. Unknown keys anywhere are errors (pbrt-v4 style): a misspelt
// key must never be silently ignored.
#pragma once

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/options.h"

namespace mmh {

class Config {
 public:
  // An empty configuration (all defaults).
  Config() = default;

  // Reads a JSON file; a parse error names the file, line and column.
  static Config Load(const std::filesystem::path& path);

  // Applies "key.path=value". The value is JSON (3, 2.5, true, "text", {...}); anything that is
  // not valid JSON is taken as a string, so `--set montage.blend.weight=smoothstep` works.
  void Set(const std::string& assignment);

  // Reads the object at `section` (e.g. "montage") into an Options struct: missing keys keep the
  // struct's defaults, unknown keys and wrong types are InputErrors naming the source, the key,
  // the value and the expectation. The struct's Validate(prefix) is called afterwards.
  template <class T>
  T Get(const std::string& section) const {
    T options;
    const auto it = root_.find(section);
    if (it != root_.end()) FromJson(*it, section, SourceOf(section), &options);
    options.Validate(section);
    return options;
  }

  // Rejects top-level keys other than `sections` (a command uses only some of them).
  void RequireOnlySections(const std::vector<std::string>& sections) const;

  const nlohmann::json& root() const { return root_; }

  // Where the value of `key_path` (or the object it lies in) came from, for messages.
  ConfigSource SourceOf(const std::string& key_path) const;

  // The folder that relative file paths in the value of `key_path` are relative to: the config
  // file's folder when the file gave the value, "" (the working directory) when a --set at, above
  // or below `key_path` did or there is no file.
  std::filesystem::path FolderOf(const std::string& key_path) const;

 private:
  nlohmann::json root_ = nlohmann::json::object();
  std::string file_;
  // key path -> the --set assignment that wrote it.
  std::map<std::string, std::string> overrides_;
};

}  // namespace mmh
