// Scenario parameters: one table declares every key once (type, unit, default, allowed
// range, help). The same table validates scenario files and --set overrides, prints the
// resolved values for `fracflow check`, and generates the README's parameter reference,
// so the three cannot drift apart.
#pragma once
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <variant>
#include <vector>

namespace ff {

enum class ParamType { Float, Int, Bool, String, FloatList, StringList };
using ParamValue = std::variant<double, long, bool, std::string, std::vector<double>, std::vector<std::string>>;

std::string to_string(ParamType t);
std::string format_value(const ParamValue& v);

struct ParamSpec {
  std::string key;   // dotted path; a segment "*" matches any name, e.g. "dem.group.*.density"
  ParamType type = ParamType::Float;
  std::string unit;  // SI unit, "-" for dimensionless
  std::string help;
  std::optional<ParamValue> default_value;  // nullopt: the key is required
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false, max_open = false;  // open interval ends (min < v rather than min <= v)
  std::vector<std::string> choices;         // allowed strings (String / StringList), empty = any
  std::size_t list_min = 0, list_max = std::numeric_limits<std::size_t>::max();  // list sizes
  // The default is a fallback that another key can replace (lbm.tau against lbm.time_step):
  // resolved_toml() writes it as a comment when it was not set, so a scenario read back (the
  // saved scenario of a resumed run) leaves it unset, as the user did.
  bool fallback_default = false;

  // Fluent setters used where the table is declared.
  ParamSpec& range(double lo, double hi) { min = lo; max = hi; return *this; }
  ParamSpec& at_least(double lo) { min = lo; return *this; }
  ParamSpec& positive() { min = 0; min_open = true; return *this; }
  ParamSpec& non_negative() { min = 0; return *this; }
  ParamSpec& open_range(double lo, double hi) { min = lo; max = hi; min_open = max_open = true; return *this; }
  ParamSpec& below(double hi) { max = hi; max_open = true; return *this; }
  ParamSpec& at_most(double hi) { max = hi; return *this; }
  ParamSpec& one_of(std::vector<std::string> c) { choices = std::move(c); return *this; }
  ParamSpec& size(std::size_t n) { list_min = list_max = n; return *this; }
  ParamSpec& size_between(std::size_t a, std::size_t b) { list_min = a; list_max = b; return *this; }
  ParamSpec& fallback() { fallback_default = true; return *this; }

  std::string allowed() const;  // human-readable "what is allowed"
  bool matches(const std::string& k) const;
};

// The declaration table of one driver (and the modules it uses).
class ParamTable {
 public:
  ParamSpec& real(std::string key, double def, std::string unit, std::string help);
  ParamSpec& real_required(std::string key, std::string unit, std::string help);
  ParamSpec& integer(std::string key, long def, std::string unit, std::string help);
  ParamSpec& boolean(std::string key, bool def, std::string help);
  ParamSpec& string(std::string key, std::string def, std::string help);
  ParamSpec& real_list(std::string key, std::vector<double> def, std::string unit, std::string help);
  ParamSpec& string_list(std::string key, std::vector<std::string> def, std::string help);

  const ParamSpec* find(const std::string& key) const;  // exact or wildcard match
  const std::vector<ParamSpec>& specs() const { return specs_; }
  // Markdown table of every key (the README's parameter reference).
  std::string markdown() const;

 private:
  ParamSpec& add(ParamSpec s);
  std::vector<ParamSpec> specs_;
  // find() is called once per key of a scenario (and per read): indexes keep it O(1) for
  // exact keys and a few candidates for wildcards (those ending in the same segment), so a
  // large file costs linear time. Positions in specs_, in declaration order.
  std::unordered_map<std::string, std::size_t> exact_;
  std::unordered_map<std::string, std::vector<std::size_t>> wild_by_leaf_;
  std::vector<std::size_t> wild_any_leaf_;  // wildcards whose last segment is "*"
};

// Where a resolved value came from.
struct ParamOrigin {
  enum Kind { Default, File, CommandLine } kind = Default;
  std::string file;
  long line = 0;
};

// Keys every run of a driver that declares them reads, some only after the set-up (intervals,
// summary fields): never reported as unused.
bool read_by_every_run(const std::string& key);

// The resolved parameters of one run: scenario file + --set overrides + defaults, validated.
class Config {
 public:
  Config() = default;
  Config(const ParamTable* table, std::string scenario_name) : table_(table), name_(std::move(scenario_name)) {}

  double real(const std::string& key) const;
  long integer(const std::string& key) const;
  bool boolean(const std::string& key) const;
  const std::string& string(const std::string& key) const;
  const std::vector<double>& real_list(const std::string& key) const;
  const std::vector<std::string>& string_list(const std::string& key) const;
  bool has(const std::string& key) const;  // set explicitly (file or --set)
  // Names that appear at a wildcard level, e.g. names("dem.group") -> {"matrix","inclusion"}.
  std::vector<std::string> names(const std::string& prefix) const;
  // Where the key was set: "file.toml:12", "--set", or "default".
  std::string origin(const std::string& key) const;
  // Error for a value that passed the table check but fails a cross-parameter check
  // (e.g. a time step above the critical one): names the file, line, key and the fix.
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

  void set(const std::string& key, ParamValue v, ParamOrigin o);
  const ParamTable& table() const { return *table_; }
  const std::string& scenario_name() const { return name_; }
  const std::map<std::string, std::pair<ParamValue, ParamOrigin>>& values() const { return values_; }
  // Every key with its resolved value (explicit and defaults; wildcard keys expanded for the
  // names present) as TOML text; parsing it back gives the same Config.
  std::string resolved_toml() const;
  // Every key with its resolved value (defaults included, wildcards expanded), sorted as the table.
  std::vector<std::pair<std::string, ParamValue>> resolved_values() const;
  // Table for `fracflow check`: key, value, unit, default, source.
  std::string describe() const;
  // Keys set explicitly (file or --set) that nothing has read (a getter or has()) so far: keys of
  // another shape, dimension or mode, which the run ignores. Copies of a Config share the record.
  // Keys that every run of their driver reads, some only after the set-up (read_by_every_run:
  // driver, title, output.*, the intervals, summary-only keys), are never named.
  std::vector<std::string> unread_keys() const;
  // From here on a first read of a key is recorded as late: unread_keys() at the end of the set-up
  // would have named it wrongly unless read_by_every_run() lists it. Tests fail on any.
  void mark_set_up_done() const { reads_->set_up_done = true; }
  std::vector<std::string> late_reads() const;

 private:
  const ParamSpec& spec(const std::string& key) const;
  const ParamValue& value(const std::string& key, ParamType t) const;
  std::vector<std::pair<std::string, const ParamSpec*>> expanded_keys() const;
  const ParamTable* table_ = nullptr;
  std::string name_;
  std::map<std::string, std::pair<ParamValue, ParamOrigin>> values_;
  struct Reads {
    std::unordered_set<std::string> keys, late;
    bool set_up_done = false;
  };
  void note_read(const std::string& key) const;
  std::shared_ptr<Reads> reads_ = std::make_shared<Reads>();
};

}  // namespace ff
