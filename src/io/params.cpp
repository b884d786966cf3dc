#include "io/params.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <string_view>
#include <unordered_set>

#include "core/error.hpp"

namespace ff {

std::string to_string(ParamType t) {
  switch (t) {
    case ParamType::Float: return "real";
    case ParamType::Int: return "integer";
    case ParamType::Bool: return "boolean";
    case ParamType::String: return "string";
    case ParamType::FloatList: return "list of reals";
    case ParamType::StringList: return "list of strings";
  }
  return "?";
}

// A TOML basic string: quotes, backslashes and control characters escaped, so that
// resolved_toml() always parses back (found by tests/fuzz).
static std::string quote(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') o += '\\';
    if (c == '\n') o += "\\n";
    else if (c == '\t') o += "\\t";
    else if (u < 0x20 || u == 0x7F) o += fmt::format("\\u{:04X}", u);
    else o += c;
  }
  return o + "\"";
}

// A dotted key as TOML: segments that are not bare keys ([A-Za-z0-9_-]+) are quoted,
// e.g. dem.contact."rock/rock".law.
static std::string toml_key(const std::string& key) {
  std::string o, seg;
  auto flush = [&] {
    const bool bare = !seg.empty() && std::all_of(seg.begin(), seg.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    });
    o += bare ? seg : quote(seg);
    seg.clear();
  };
  for (char c : key) {
    if (c == '.') {
      flush();
      o += '.';
    } else {
      seg += c;
    }
  }
  flush();
  return o;
}

std::string format_value(const ParamValue& v) {
  struct V {
    std::string operator()(double d) const {
      std::string s = fmt::format("{}", d);  // shortest round-trip form
      if (std::isfinite(d) && s.find_first_of(".eEn") == std::string::npos) s += ".0";
      return s;
    }
    std::string operator()(long i) const { return std::to_string(i); }
    std::string operator()(bool b) const { return b ? "true" : "false"; }
    std::string operator()(const std::string& s) const { return quote(s); }
    std::string operator()(const std::vector<double>& l) const {
      std::string o = "[";
      for (std::size_t i = 0; i < l.size(); ++i) o += (i ? ", " : "") + (*this)(l[i]);
      return o + "]";
    }
    std::string operator()(const std::vector<std::string>& l) const {
      std::string o = "[";
      for (std::size_t i = 0; i < l.size(); ++i) o += (i ? ", " : "") + quote(l[i]);
      return o + "]";
    }
  };
  return std::visit(V{}, v);
}

static std::string fmt_num(double d) { return fmt::format("{}", d); }

std::string ParamSpec::allowed() const {
  std::string a = to_string(type);
  if (!choices.empty()) {
    a += " , one of:";
    for (auto& c : choices) {
      a += ' ';  // appended in two steps: `" " + quote(c)` trips GCC 12's false -Wrestrict (PR 105329)
      a += quote(c);
    }
  }
  const bool lo = std::isfinite(min), hi = std::isfinite(max);
  if (type == ParamType::Float || type == ParamType::Int || type == ParamType::FloatList) {
    if (lo && hi) a += fmt::format(" in {}{}, {}{}", min_open ? "(" : "[", fmt_num(min), fmt_num(max), max_open ? ")" : "]");
    else if (lo) a += fmt::format(" {} {}", min_open ? ">" : ">=", fmt_num(min));
    else if (hi) a += fmt::format(" {} {}", max_open ? "<" : "<=", fmt_num(max));
  }
  if (type == ParamType::FloatList || type == ParamType::StringList) {
    if (list_min == list_max) a += fmt::format(" with {} entries", list_min);
    else if (list_min > 0 || list_max != std::numeric_limits<std::size_t>::max())
      a += fmt::format(" with {}..{} entries", list_min,
                       list_max == std::numeric_limits<std::size_t>::max() ? std::string("any") : std::to_string(list_max));
  }
  return a;
}

// Segment-wise comparison without allocating (find() runs once per key of a scenario).
bool ParamSpec::matches(const std::string& k) const {
  if (key.find('*') == std::string::npos) return key == k;
  std::size_t i = 0, j = 0;  // positions in key and k
  for (;;) {
    const std::size_t ie = std::min(key.find('.', i), key.size()), je = std::min(k.find('.', j), k.size());
    const std::string_view a(key.data() + i, ie - i), b(k.data() + j, je - j);
    if (a != "*" && a != b) return false;
    const bool a_end = ie == key.size(), b_end = je == k.size();
    if (a_end || b_end) return a_end && b_end;
    i = ie + 1;
    j = je + 1;
  }
}

static std::string last_segment(const std::string& k) {
  const auto dot = k.rfind('.');
  return dot == std::string::npos ? k : k.substr(dot + 1);
}

ParamSpec& ParamTable::add(ParamSpec s) {
  if (exact_.count(s.key)) throw Error("internal: parameter '" + s.key + "' declared twice");
  const std::size_t at = specs_.size();
  exact_.emplace(s.key, at);
  if (s.key.find('*') != std::string::npos) {
    const std::string leaf = last_segment(s.key);
    if (leaf == "*") wild_any_leaf_.push_back(at);
    else wild_by_leaf_[leaf].push_back(at);
  }
  specs_.push_back(std::move(s));
  return specs_.back();
}
static ParamSpec make_spec(std::string key, ParamType type, std::string unit, std::string help,
                           std::optional<ParamValue> def) {
  ParamSpec s;
  s.key = std::move(key);
  s.type = type;
  s.unit = std::move(unit);
  s.help = std::move(help);
  s.default_value = std::move(def);
  return s;
}
ParamSpec& ParamTable::real(std::string key, double def, std::string unit, std::string help) {
  return add(make_spec(std::move(key), ParamType::Float, std::move(unit), std::move(help), ParamValue{def}));
}
ParamSpec& ParamTable::real_required(std::string key, std::string unit, std::string help) {
  return add(make_spec(std::move(key), ParamType::Float, std::move(unit), std::move(help), std::nullopt));
}
ParamSpec& ParamTable::integer(std::string key, long def, std::string unit, std::string help) {
  return add(make_spec(std::move(key), ParamType::Int, std::move(unit), std::move(help), ParamValue{def}));
}
ParamSpec& ParamTable::boolean(std::string key, bool def, std::string help) {
  return add(make_spec(std::move(key), ParamType::Bool, "-", std::move(help), ParamValue{def}));
}
ParamSpec& ParamTable::string(std::string key, std::string def, std::string help) {
  return add(make_spec(std::move(key), ParamType::String, "-", std::move(help), ParamValue{std::move(def)}));
}
ParamSpec& ParamTable::real_list(std::string key, std::vector<double> def, std::string unit, std::string help) {
  return add(make_spec(std::move(key), ParamType::FloatList, std::move(unit), std::move(help), ParamValue{std::move(def)}));
}
ParamSpec& ParamTable::string_list(std::string key, std::vector<std::string> def, std::string help) {
  return add(make_spec(std::move(key), ParamType::StringList, "-", std::move(help), ParamValue{std::move(def)}));
}

const ParamSpec* ParamTable::find(const std::string& key) const {
  if (auto it = exact_.find(key); it != exact_.end()) return &specs_[it->second];  // exact names win over wildcards
  // The first wildcard in declaration order that matches.
  std::size_t best = specs_.size();
  if (auto it = wild_by_leaf_.find(last_segment(key)); it != wild_by_leaf_.end())
    for (std::size_t i : it->second)
      if (specs_[i].matches(key)) {
        best = i;
        break;
      }
  for (std::size_t i : wild_any_leaf_) {
    if (i >= best) break;
    if (specs_[i].matches(key)) {
      best = i;
      break;
    }
  }
  return best < specs_.size() ? &specs_[best] : nullptr;
}

std::string ParamTable::markdown() const {
  std::string o = "| key | type | unit | default | allowed | meaning |\n|---|---|---|---|---|---|\n";
  for (auto& s : specs_) {
    std::string allowed = s.allowed();
    auto esc = [](std::string t) {
      std::string r;
      for (char c : t) r += (c == '|') ? std::string("\\|") : std::string(1, c);
      return r;
    };
    o += fmt::format("| `{}` | {} | {} | {} | {} | {} |\n", s.key, to_string(s.type), s.unit,
                     s.default_value ? fmt::format("`{}`", format_value(*s.default_value)) : std::string("required"),
                     esc(allowed), esc(s.help));
  }
  return o;
}

// ---------------------------------------------------------------- Config

const ParamSpec& Config::spec(const std::string& key) const {
  const ParamSpec* s = table_ ? table_->find(key) : nullptr;
  if (!s) throw Error("internal: parameter '" + key + "' is read but was never declared");
  return *s;
}

void Config::note_read(const std::string& key) const {
#pragma omp critical(ff_config_reads)
  {
    if (reads_->keys.insert(key).second && reads_->set_up_done) reads_->late.insert(key);
  }
}

bool read_by_every_run(const std::string& key) {
  static const std::unordered_set<std::string> kLate = {
      "driver",          "title",          "measure.pressure",    "measure.angles",
      "insitu.tolerance", "injection.stop_extent",
      "dem.energy_tracking", "run.steady_tolerance", "reference.terminal_velocity",
      "triaxial.measurement_sphere_radius"};
  auto ends = [&](std::string_view s) { return key.size() >= s.size() && key.compare(key.size() - s.size(), s.size(), s) == 0; };
  return kLate.count(key) || key.rfind("output.", 0) == 0 || ends(".series_interval") || ends(".checkpoint_interval") ||
         ends(".vtk_interval");
}

std::vector<std::string> Config::unread_keys() const {
  std::vector<std::string> out;
  for (const auto& [k, v] : values_)
    if (v.second.kind != ParamOrigin::Default && !reads_->keys.count(k) && !read_by_every_run(k)) out.push_back(k);
  return out;
}

std::vector<std::string> Config::late_reads() const {
  std::vector<std::string> out;
  for (const auto& k : reads_->late)
    if (!read_by_every_run(k)) out.push_back(k);
  std::sort(out.begin(), out.end());
  return out;
}

const ParamValue& Config::value(const std::string& key, ParamType t) const {
  note_read(key);
  const ParamSpec& s = spec(key);
  if (s.type != t) throw Error("internal: parameter '" + key + "' is a " + to_string(s.type) + ", read as " + to_string(t));
  auto it = values_.find(key);
  if (it != values_.end()) return it->second.first;
  if (!s.default_value)
    throw InputError(fmt::format("{}: required key '{}' is missing ({} [{}]: {})", name_, key, s.allowed(), s.unit, s.help));
  return *s.default_value;
}

double Config::real(const std::string& k) const { return std::get<double>(value(k, ParamType::Float)); }
long Config::integer(const std::string& k) const { return std::get<long>(value(k, ParamType::Int)); }
bool Config::boolean(const std::string& k) const { return std::get<bool>(value(k, ParamType::Bool)); }
const std::string& Config::string(const std::string& k) const { return std::get<std::string>(value(k, ParamType::String)); }
const std::vector<double>& Config::real_list(const std::string& k) const {
  return std::get<std::vector<double>>(value(k, ParamType::FloatList));
}
const std::vector<std::string>& Config::string_list(const std::string& k) const {
  return std::get<std::vector<std::string>>(value(k, ParamType::StringList));
}
bool Config::has(const std::string& key) const {
  note_read(key);
  return values_.count(key) > 0;
}

std::vector<std::string> Config::names(const std::string& prefix) const {
  // Keys with the prefix are contiguous in the sorted map; a set keeps the scan linear.
  std::vector<std::string> out;
  std::unordered_set<std::string> seen;
  const std::string p = prefix + ".";
  for (auto it = values_.lower_bound(p); it != values_.end() && it->first.compare(0, p.size(), p) == 0; ++it) {
    std::string name = it->first.substr(p.size(), it->first.find('.', p.size()) - p.size());
    if (seen.insert(name).second) out.push_back(std::move(name));
  }
  return out;
}

std::string Config::origin(const std::string& key) const {
  auto it = values_.find(key);
  if (it == values_.end()) return "default";
  const ParamOrigin& o = it->second.second;
  if (o.kind == ParamOrigin::CommandLine) return "--set";
  return o.line > 0 ? fmt::format("{}:{}", o.file, o.line) : o.file;
}

void Config::fail(const std::string& key, const std::string& what) const {
  std::string where = origin(key);
  if (where == "default") where = name_ + " (default value)";
  throw InputError(fmt::format("{}: key '{}': {}", where, key, what));
}

void Config::set(const std::string& key, ParamValue v, ParamOrigin o) { values_[key] = {std::move(v), std::move(o)}; }

std::vector<std::pair<std::string, const ParamSpec*>> Config::expanded_keys() const {
  // One pass sorts the explicit keys by their spec (values_ is sorted, so each list is too);
  // the names at a wildcard level are listed once per prefix. Linear in the number of keys.
  std::unordered_map<const ParamSpec*, std::vector<std::string>> explicit_keys;
  for (auto& [k, v] : values_)
    if (const ParamSpec* s = table_->find(k)) explicit_keys[s].push_back(k);
  std::unordered_map<std::string, std::vector<std::string>> names_at;
  std::vector<std::pair<std::string, const ParamSpec*>> out;
  for (auto& s : table_->specs()) {
    if (s.key.find('*') == std::string::npos) { out.emplace_back(s.key, &s); continue; }
    std::vector<std::string> keys;
    if (auto it = explicit_keys.find(&s); it != explicit_keys.end()) keys = it->second;
    const std::size_t n_explicit = keys.size();
    // Also instantiate defaults for names present at the wildcard's level.
    const auto pos = s.key.find('*');
    const std::string prefix = s.key.substr(0, pos == 0 ? 0 : pos - 1);
    const std::string suffix = s.key.substr(pos + 1);
    if (suffix.find('*') == std::string::npos) {
      auto [it, fresh] = names_at.try_emplace(prefix);
      if (fresh) it->second = names(prefix);
      for (auto& name : it->second) {
        std::string k = prefix + "." + name + suffix;
        if (!values_.count(k) && table_->find(k) == &s) keys.push_back(std::move(k));
      }
    }
    if (keys.size() > n_explicit) std::sort(keys.begin(), keys.end());
    for (auto& k : keys) out.emplace_back(std::move(k), &s);
  }
  return out;
}

std::string Config::resolved_toml() const {
  // Flat dotted keys are valid TOML and keep the file greppable.
  std::string o = fmt::format("# Resolved parameters of {} (every key, defaults included).\n", name_);
  for (auto& [k, s] : expanded_keys()) {
    auto it = values_.find(k);
    if (it != values_.end()) o += fmt::format("{} = {}\n", toml_key(k), format_value(it->second.first));
    else if (s->default_value)
      o += fmt::format("{}{} = {}\n", s->fallback_default ? "# (default, not set) " : "", toml_key(k),
                       format_value(*s->default_value));
  }
  return o;
}

std::vector<std::pair<std::string, ParamValue>> Config::resolved_values() const {
  std::vector<std::pair<std::string, ParamValue>> out;
  for (auto& [k, s] : expanded_keys()) {
    auto it = values_.find(k);
    if (it != values_.end()) out.emplace_back(k, it->second.first);
    else if (s->default_value) out.emplace_back(k, *s->default_value);
  }
  return out;
}

std::string Config::describe() const {
  std::vector<std::array<std::string, 5>> rows;
  rows.push_back({"key", "value", "unit", "default", "source"});
  for (auto& [k, s] : expanded_keys()) {
    auto it = values_.find(k);
    std::string val = it != values_.end() ? format_value(it->second.first)
                      : s->default_value ? format_value(*s->default_value) : "(missing!)";
    rows.push_back({k, val, s->unit, s->default_value ? format_value(*s->default_value) : "required", origin(k)});
  }
  std::array<std::size_t, 5> w{};
  for (auto& r : rows)
    for (int i = 0; i < 5; ++i) w[i] = std::max(w[i], std::min<std::size_t>(r[i].size(), 48));
  std::string o;
  for (auto& r : rows) {
    for (int i = 0; i < 5; ++i) o += fmt::format("{:<{}}  ", r[i], w[i]);
    while (!o.empty() && o.back() == ' ') o.pop_back();
    o += '\n';
  }
  return o;
}

}  // namespace ff
