// Reading scenario files (TOML) into a validated Config.
#pragma once
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "io/params.hpp"

namespace ff {

// A scenario holds at most this many keys (key = value pairs, file and --set together). The
// largest valid scenario (kMaxGroups groups with every pair table, kMaxRegions regions) has
// about 160,000 once resolved (every default written out, as in a results folder's
// scenario.toml); a bigger file is refused before it is parsed.
inline constexpr std::size_t kMaxScenarioKeys = 200000;

// One leaf of a TOML document, flattened to a dotted key.
struct RawEntry {
  std::string key;
  ParamValue value;
  ParamType type;  // what the file wrote (Real for numbers, lists by their elements)
  long line = 0;
};

// Parses TOML text into flat entries. `source` names the text in error messages.
// Throws InputError("source:line: ...") for syntax errors; never crashes on any input
// (guards for toml++ 3.3.0's known crashes; fuzzed by tests/fuzz).
std::vector<RawEntry> parse_toml_flat(std::string_view text, const std::string& source);

// The value of `driver` in the text, or "" when absent (does not validate anything else).
std::string peek_driver(std::string_view text, const std::string& source);
std::string peek_driver(const std::vector<RawEntry>& entries, const std::string& source);

// Validates `entries` and the `--set key=value` overrides against `table`: unknown keys,
// wrong types, out-of-range values and bad choices all throw InputError naming the source,
// line, key, what was wrong and what is allowed.
Config build_config(const ParamTable& table, const std::string& source, const std::vector<RawEntry>& entries,
                    const std::vector<std::string>& overrides);

// Reads a file (or uses `builtin_text` when `path` is empty) and builds the Config. A file
// (path not empty) that sets no key at all (empty, only a byte-order mark, blanks or comments)
// is refused: it is almost always the wrong file, and would silently run the defaults.
Config load_scenario(const ParamTable& table, const std::string& path, std::string_view text,
                     const std::vector<std::string>& overrides);
// The same from entries already parsed from the text (parse_toml_flat(text, path)).
Config load_scenario(const ParamTable& table, const std::string& path, const std::vector<RawEntry>& entries,
                     const std::vector<std::string>& overrides);

// Throws InputError naming the path when it is missing, a folder or not readable.
std::string read_text_file(const std::string& path);

}  // namespace ff
