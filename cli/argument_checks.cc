#include "cli/argument_checks.h"

#include <algorithm>

#include "core/error.h"
#include "core/error_text.h"
#include "core/resource_limits.h"

namespace mmh::cli {

void CheckArguments(const std::vector<std::string>& args,
                    const std::vector<std::string>& subcommands) {
  if (args.size() >= 2 && !args[1].empty() && args[1].front() != '-' &&
      std::find(subcommands.begin(), subcommands.end(), args[1]) == subcommands.end()) {
    std::string names;
    for (const std::string& name : subcommands) names += (names.empty() ? "" : ", ") + name;
    ThrowBadValue("mmh", "the unknown subcommand " + Quote(args[1], 40), "one of: " + names);
  }
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string& arg = args[i];
    // "--flag value" or "--flag=value"; a flag at the end without value is CLI11's to report.
    auto value_of = [&](const std::string& flag, std::string* value) {
      if (arg == flag && i + 1 < args.size()) {
        *value = args[i + 1];
        return true;
      }
      if (arg.starts_with(flag + "=")) {
        *value = arg.substr(flag.size() + 1);
        return true;
      }
      return false;
    };
    std::string value;
    if (value_of("--threads", &value)) ParseThreadCount(value, "--threads");
    if (value_of("--out", &value) && value.empty()) {
      ThrowBadValue("--out", "an empty path", "the path of an output folder");
    }
  }
}

}  // namespace mmh::cli
