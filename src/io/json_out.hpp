// JSON summaries (run metadata, measured strengths, timings) written atomically.
#pragma once
#include <filesystem>
#include <nlohmann/json.hpp>

namespace ff {

// Writes `j` with indent 2 and a final newline, atomically; NaN and infinities become null,
// invalid UTF-8 in strings is replaced by U+FFFD. Throws ff::Error naming the path on failure.
void write_json_atomic(const std::filesystem::path& path, const nlohmann::json& j);

}  // namespace ff
