// JSON (de)serialisation of Options structs (Ceres style: one struct per algorithm, defaults in
// the struct). An Options struct lists its fields once:
//
//   struct DtwOptions {
//     double lambda = 2.5;  // unit, meaning, source
//     template <class V> void VisitFields(V& v) { v("lambda", lambda); }
//     void Validate(const std::string& prefix) const;  // throws InputError naming prefix + field
//   };
//
// and gets ToJson (every default filled in: the resolved config) and FromJson (missing keys keep
// their defaults, unknown keys and wrong types are InputErrors naming the source, key path, value
// and expectation, with a did-you-mean suggestion). Supported field types: bool, integers,
// floating point, std::string, enums with an EnumNames(E) overload, nested Options structs, and
// std::vector of nested Options structs (a JSON array of objects; keys in messages as
// "scene.objects[1].mesh").
#pragma once

#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/error.h"

namespace mmh {

// Where a JSON value came from, for messages: "configs/a.json" or "--set montage.mu=3".
struct ConfigSource {
  std::string name;
};

// An enum E is (de)serialised by name when `EnumNames(E{})` (found by ADL) returns a
// std::span<const std::pair<E, const char*>>.
template <class E>
concept NamedEnum = std::is_enum_v<E> && requires(E e) {
  { EnumNames(e) } -> std::convertible_to<std::span<const std::pair<E, const char*>>>;
};

template <class E>
requires NamedEnum<E>
const char* EnumName(E value) {
  for (const auto& [e, name] : EnumNames(value)) {
    if (e == value) return name;
  }
  return "?";
}

namespace options_internal {

struct FieldCollector {
  std::vector<std::string> names;
  template <class T>
  void operator()(const char* name, T&) {
    names.emplace_back(name);
  }
};

template <class T>
concept HasFields = requires(T& t, FieldCollector& c) {
  t.VisitFields(c);
};

template <class T>
struct IsFieldsVector : std::false_type {};
template <class T>
requires HasFields<T>
struct IsFieldsVector<std::vector<T>> : std::true_type {
};

// The closest known name within edit distance 2, or "".
std::string SuggestName(const std::string& unknown, const std::vector<std::string>& known);

[[noreturn]] void ThrowKeyError(const ConfigSource& source, const std::string& key,
                                const nlohmann::json& value, const std::string& expected);

std::string JoinNames(const std::vector<std::string>& names);

}  // namespace options_internal

template <class T>
nlohmann::json ToJson(const T& options);

template <class T>
void FromJson(const nlohmann::json& json, const std::string& key_path, const ConfigSource& source,
              T* options);

namespace options_internal {

struct ToJsonVisitor {
  nlohmann::json* json;
  template <class T>
  void operator()(const char* name, T& field) {
    if constexpr (HasFields<T>) {
      (*json)[name] = ToJson(field);
    } else if constexpr (IsFieldsVector<T>::value) {
      nlohmann::json array = nlohmann::json::array();
      for (const auto& element : field) array.push_back(ToJson(element));
      (*json)[name] = std::move(array);
    } else if constexpr (NamedEnum<T>) {
      (*json)[name] = EnumName(field);
    } else {
      (*json)[name] = field;
    }
  }
};

template <class T>
void ReadValue(const nlohmann::json& value, const std::string& key, const ConfigSource& source,
               T* field) {
  if constexpr (HasFields<T>) {
    FromJson(value, key, source, field);
  } else if constexpr (IsFieldsVector<T>::value) {
    // The array replaces the default list; each element starts from the element's defaults.
    if (!value.is_array()) ThrowKeyError(source, key, value, "an array of objects");
    T elements(value.size());
    for (size_t i = 0; i < value.size(); ++i) {
      FromJson(value[i], key + "[" + std::to_string(i) + "]", source, &elements[i]);
    }
    *field = std::move(elements);
  } else if constexpr (NamedEnum<T>) {
    std::vector<std::string> names;
    for (const auto& [e, name] : EnumNames(T{})) names.emplace_back(name);
    if (value.is_string()) {
      for (const auto& [e, name] : EnumNames(T{})) {
        if (value.get<std::string>() == name) {
          *field = e;
          return;
        }
      }
    }
    ThrowKeyError(source, key, value, "one of " + JoinNames(names));
  } else if constexpr (std::is_same_v<T, bool>) {
    if (!value.is_boolean()) ThrowKeyError(source, key, value, "true or false");
    *field = value.get<bool>();
  } else if constexpr (std::is_integral_v<T>) {
    // Unsigned and signed JSON integers are range-checked separately: no wrap-around.
    if (value.is_number_unsigned()) {
      const auto v = value.get<std::uint64_t>();
      if (v <= static_cast<std::uint64_t>(std::numeric_limits<T>::max())) {
        *field = static_cast<T>(v);
        return;
      }
    } else if (value.is_number_integer()) {
      const auto v = value.get<std::int64_t>();
      const bool fits =
          std::is_signed_v<T>
              ? v >= static_cast<std::int64_t>(std::numeric_limits<T>::min()) &&
                    v <= static_cast<std::int64_t>(std::numeric_limits<T>::max())
              : v >= 0 && static_cast<std::uint64_t>(v) <=
                              static_cast<std::uint64_t>(std::numeric_limits<T>::max());
      if (fits) {
        *field = static_cast<T>(v);
        return;
      }
    }
    ThrowKeyError(source, key, value,
                  "an integer in [" + std::to_string(std::numeric_limits<T>::min()) + ", " +
                      std::to_string(std::numeric_limits<T>::max()) + "]");
  } else if constexpr (std::is_floating_point_v<T>) {
    if (!value.is_number()) ThrowKeyError(source, key, value, "a number");
    const double v = value.get<double>();
    if (!(std::abs(v) <= static_cast<double>(std::numeric_limits<T>::max()))) {
      ThrowKeyError(source, key, value, "a finite number of this field's precision");
    }
    *field = static_cast<T>(v);
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (!value.is_string()) ThrowKeyError(source, key, value, "a string");
    *field = value.get<std::string>();
  } else {
    static_assert(sizeof(T) == 0, "unsupported option field type");
  }
}

struct FromJsonVisitor {
  const nlohmann::json* json;
  const std::string* key_path;
  const ConfigSource* source;
  std::vector<std::string>* seen;
  template <class T>
  void operator()(const char* name, T& field) {
    seen->emplace_back(name);
    const auto it = json->find(name);
    if (it == json->end()) return;
    const std::string key = key_path->empty() ? name : *key_path + "." + name;
    ReadValue(*it, key, *source, &field);
  }
};

}  // namespace options_internal

template <class T>
nlohmann::json ToJson(const T& options) {
  nlohmann::json json = nlohmann::json::object();
  T copy = options;  // VisitFields takes a mutable reference; serialising never changes it
  options_internal::ToJsonVisitor visitor{&json};
  copy.VisitFields(visitor);
  return json;
}

template <class T>
void FromJson(const nlohmann::json& json, const std::string& key_path, const ConfigSource& source,
              T* options) {
  if (!json.is_object()) {
    options_internal::ThrowKeyError(source, key_path.empty() ? "(top level)" : key_path, json,
                                    "an object of options");
  }
  std::vector<std::string> known;
  options_internal::FromJsonVisitor visitor{&json, &key_path, &source, &known};
  options->VisitFields(visitor);
  for (auto it = json.begin(); it != json.end(); ++it) {
    bool found = false;
    for (const auto& name : known) found = found || name == it.key();
    if (found) continue;
    const std::string key = key_path.empty() ? it.key() : key_path + "." + it.key();
    const std::string suggestion = options_internal::SuggestName(it.key(), known);
    throw InputError(source.name + ": key '" + key + "' is unknown" +
                     (suggestion.empty() ? "" : " (did you mean '" + suggestion + "'?)") +
                     "; known keys here: " + options_internal::JoinNames(known));
  }
}

}  // namespace mmh
