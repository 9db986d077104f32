// Checks of the command line that CLI11 makes poorly, run before it parses: an unknown subcommand
// is named (CLI11 says only "A subcommand is required"), --threads is bounded with a short message
// (CLI11's range check prints the largest double in 310 digits), and an empty --out is named.
#pragma once

#include <string>
#include <vector>

namespace mmh::cli {

// Throws InputError for the first problem in `args` (argv, program name first); `subcommands`
// are the names of the registered subcommands.
void CheckArguments(const std::vector<std::string>& args,
                    const std::vector<std::string>& subcommands);

}  // namespace mmh::cli
