// The page data of a sweep folder (`mmh sweep`, after `mmh sweep aggregate`): the plan (axes,
// cells done / failed / missing), the aggregate tables as written, and each metric against each
// numeric axis (mean over the other axes with its 95 % CI, as plots/<metric>_vs_<axis>.svg).
#pragma once

#include <filesystem>
#include <nlohmann/json_fwd.hpp>

namespace mmh::report {

// InputError naming the file when plan.json or an aggregate table (results.csv, summary.csv,
// failures.csv, variance_shares.csv) is missing or malformed.
nlohmann::json SweepData(const std::filesystem::path& dir);

}  // namespace mmh::report
