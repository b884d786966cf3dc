#include "io/scenario.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <toml++/toml.h>

#include "core/error.hpp"

namespace ff {

std::string read_text_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))  // an ifstream opens a folder and reads it as empty
    throw InputError(fmt::format("'{}' is a folder, not a scenario file; give a .toml file (e.g. examples/ucs_default.toml)",
                                 path));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("cannot open scenario file '{}': no such file or not readable", path));
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

namespace {

// toml++ 3.3.0 (Debian 12) reads past the end of a buffer that holds only a UTF-8
// byte-order mark, and a few truncated UTF-8 sequences at the very end of the input.
// Dropping the BOM and rejecting invalid UTF-8 before parsing removes those paths.
std::string sanitize(std::string_view text, const std::string& source) {
  if (text.size() >= 3 && static_cast<unsigned char>(text[0]) == 0xEF && static_cast<unsigned char>(text[1]) == 0xBB &&
      static_cast<unsigned char>(text[2]) == 0xBF)
    text.remove_prefix(3);
  long line = 1;
  for (std::size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '\n') ++line;
    if (c == 0) throw InputError(fmt::format("{}:{}: the file contains a NUL byte (is it a text file?)", source, line));
    std::size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    if (n == 0 || i + n > text.size())
      throw InputError(fmt::format("{}:{}: invalid UTF-8 byte 0x{:02X}; scenario files must be UTF-8 text", source, line, c));
    for (std::size_t k = 1; k < n; ++k)
      if ((static_cast<unsigned char>(text[i + k]) >> 6) != 0x2)
        throw InputError(fmt::format("{}:{}: invalid UTF-8 sequence; scenario files must be UTF-8 text", source, line));
    i += n;
  }
  return std::string(text);
}

// toml++ 3.3.0 decides whether a non-ASCII code point is whitespace through a table that hits
// TOML_UNREACHABLE (undefined behaviour, in Debian's release build too) for e.g. U+00A1..U+0499
// (upstream issues #190 and #295), and it asks that wherever it scans bare tokens: after a key,
// in a number, after a line-ending backslash... (found by tests/fuzz). So toml++ is only ever
// given ASCII: non-ASCII characters in basic strings become \uXXXX escapes, literal strings
// become equivalent basic strings, comments lose theirs, and anywhere else (never valid TOML
// 1.0) they are an error. Newlines are kept, so line numbers in messages stay right.
// `keys` counts the '=' outside strings and comments: one per key = value pair.
std::string to_ascii_toml(std::string_view t, const std::string& source, std::size_t& keys) {
  enum State { Normal, Comment, Basic, Literal, MultiBasic, MultiLiteral } st = Normal;
  std::string o;
  o.reserve(t.size() + t.size() / 8);
  long line = 1;
  auto at = [&](std::size_t i) { return i < t.size() ? t[i] : '\0'; };
  auto run = [&](std::size_t i, char q) { std::size_t n = 0; while (at(i + n) == q) ++n; return n; };
  auto error = [&](const std::string& what) { return InputError(fmt::format("{}:{}: {}", source, line, what)); };
  for (std::size_t i = 0; i < t.size();) {
    const auto c = static_cast<unsigned char>(t[i]);
    if (c >= 0x80) {  // one code point; sanitize() checked the byte structure
      const std::size_t n = (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : 4;
      char32_t cp = c & (n == 2 ? 0x1F : n == 3 ? 0x0F : 0x07);
      for (std::size_t k = 1; k < n; ++k) cp = (cp << 6) | (static_cast<unsigned char>(t[i + k]) & 0x3F);
      const char32_t min = n == 2 ? 0x80 : n == 3 ? 0x800 : 0x10000;
      if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
        throw error("invalid UTF-8 sequence; scenario files must be UTF-8 text");
      if (st == Normal)
        throw error("non-ASCII character outside a string or comment; quote names that use one, e.g. "
                    "[dem.group.\"gr\\u00e8s\"]");
      if (st == Comment) o += '?';
      else o += cp <= 0xFFFF ? fmt::format("\\u{:04X}", static_cast<std::uint32_t>(cp))
                             : fmt::format("\\U{:08X}", static_cast<std::uint32_t>(cp));
      i += n;
      continue;
    }
    const char ch = static_cast<char>(c);
    if (ch == '\n') ++line;
    std::size_t used = 1;  // bytes consumed from t
    switch (st) {
      case Normal:
        if (ch == '#') st = Comment;
        if (ch == '=') ++keys;
        if (ch == '"' || ch == '\'') {
          const bool multi = run(i, ch) >= 3;
          st = ch == '"' ? (multi ? MultiBasic : Basic) : (multi ? MultiLiteral : Literal);
          used = multi ? 3 : 1;
          o += multi ? "\"\"\"" : "\"";
        } else {
          o += ch;
        }
        break;
      case Comment:
        if (ch == '\n') st = Normal;
        o += ch;
        break;
      case Basic:
      case MultiBasic:
        if (ch == '\\' && static_cast<unsigned char>(at(i + 1)) >= 0x80)
          throw error("a backslash followed by a non-ASCII character is not a valid escape sequence");
        if (ch == '\\' && at(i + 1) != '\0' && at(i + 1) != '\n') {  // escape: copy both characters
          o += t.substr(i, 2);
          used = 2;
        } else if (st == Basic && (ch == '"' || ch == '\n')) {
          st = Normal;
          o += ch;
        } else if (st == MultiBasic && run(i, '"') >= 3) {
          used = std::min<std::size_t>(run(i, '"'), 5);  // up to two quotes before the closing three are content
          o.append(used, '"');
          st = Normal;
        } else {
          o += ch;
        }
        break;
      case Literal:
      case MultiLiteral:
        if (st == Literal && (ch == '\'' || ch == '\n')) {
          st = Normal;
          o += ch == '\'' ? '"' : '\n';
        } else if (st == MultiLiteral && run(i, '\'') >= 3) {
          used = run(i, '\'');
          if (used > 5) throw error("more than five quotes in a row end a multi-line literal string");
          o.append(used - 3, '\'');
          o += "\"\"\"";
          st = Normal;
        } else if (ch == '"' || ch == '\\') {  // literal text, escaped for the basic string it becomes
          o += '\\';
          o += ch;
        } else {
          o += ch;
        }
        break;
    }
    i += used;
  }
  return o;
}

long line_of(const toml::node& n) { return static_cast<long>(n.source().begin.line); }

void flatten(const toml::table& t, const std::string& prefix, const std::string& source, std::vector<RawEntry>& out);

void add_leaf(const toml::node& n, const std::string& key, const std::string& source, std::vector<RawEntry>& out) {
  const long line = line_of(n);
  if (auto v = n.as_floating_point()) { out.push_back({key, ParamValue{v->get()}, ParamType::Float, line}); return; }
  if (auto v = n.as_integer()) { out.push_back({key, ParamValue{static_cast<long>(v->get())}, ParamType::Int, line}); return; }
  if (auto v = n.as_boolean()) { out.push_back({key, ParamValue{v->get()}, ParamType::Bool, line}); return; }
  if (auto v = n.as_string()) { out.push_back({key, ParamValue{std::string(v->get())}, ParamType::String, line}); return; }
  if (auto a = n.as_array()) {
    if (a->empty()) { out.push_back({key, ParamValue{std::vector<double>{}}, ParamType::FloatList, line}); return; }
    if (a->is_array_of_tables()) {  // [[x]] blocks: flattened with their index as name
      for (std::size_t i = 0; i < a->size(); ++i) flatten(*a->get(i)->as_table(), key + "." + std::to_string(i), source, out);
      return;
    }
    bool all_num = true, all_str = true;
    for (auto& e : *a) {
      all_num = all_num && (e.is_floating_point() || e.is_integer());
      all_str = all_str && e.is_string();
    }
    if (all_num) {
      std::vector<double> l;
      for (auto& e : *a) l.push_back(e.is_integer() ? static_cast<double>(e.as_integer()->get()) : e.as_floating_point()->get());
      out.push_back({key, ParamValue{std::move(l)}, ParamType::FloatList, line});
      return;
    }
    if (all_str) {
      std::vector<std::string> l;
      for (auto& e : *a) l.emplace_back(e.as_string()->get());
      out.push_back({key, ParamValue{std::move(l)}, ParamType::StringList, line});
      return;
    }
    throw InputError(fmt::format("{}:{}: key '{}': an array must hold only numbers or only strings", source, line, key));
  }
  throw InputError(fmt::format("{}:{}: key '{}': dates and times are not used by fracflow", source, line, key));
}

void flatten(const toml::table& t, const std::string& prefix, const std::string& source, std::vector<RawEntry>& out) {
  for (auto& [k, node] : t) {
    const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    // Keys are handled as dotted paths: a quoted name that is empty or holds a dot would
    // silently become another key (and not survive resolved_toml()).
    if (k.str().empty() || k.str().find('.') != std::string_view::npos)
      throw InputError(fmt::format("{}:{}: key '{}': a name may not be empty or contain a dot", source,
                                   static_cast<long>(k.source().begin.line), key));
    if (auto sub = node.as_table()) flatten(*sub, key, source, out);
    else add_leaf(node, key, source, out);
  }
}

// Converts what the file wrote to the declared type, or explains why it cannot.
ParamValue coerce(const ParamSpec& s, const RawEntry& e, const std::string& where) {
  auto wrong = [&]() -> InputError {
    return InputError(fmt::format("{}: key '{}' = {} has the wrong type: expected {} [{}] ({})", where, e.key,
                                  format_value(e.value), s.allowed(), s.unit, s.help));
  };
  switch (s.type) {
    case ParamType::Float:
      if (e.type == ParamType::Float) return e.value;
      if (e.type == ParamType::Int) return ParamValue{static_cast<double>(std::get<long>(e.value))};
      throw wrong();
    case ParamType::Int:
      if (e.type == ParamType::Int) return e.value;
      throw wrong();
    case ParamType::Bool:
      if (e.type == ParamType::Bool) return e.value;
      throw wrong();
    case ParamType::String:
      if (e.type == ParamType::String) return e.value;
      throw wrong();
    case ParamType::FloatList:
      if (e.type == ParamType::FloatList) return e.value;
      throw wrong();
    case ParamType::StringList:
      if (e.type == ParamType::StringList) return e.value;
      if (e.type == ParamType::FloatList && std::get<std::vector<double>>(e.value).empty())
        return ParamValue{std::vector<std::string>{}};
      throw wrong();
  }
  throw wrong();
}

void check_range(const ParamSpec& s, const std::string& key, const ParamValue& v, const std::string& where) {
  auto bad = [&](const std::string& what) {
    throw InputError(fmt::format("{}: key '{}' = {} {}: allowed {} [{}] ({})", where, key, format_value(v), what,
                                 s.allowed(), s.unit, s.help));
  };
  auto num_ok = [&](double d) {
    if (!std::isfinite(d)) return false;
    if (s.min_open ? !(d > s.min) : !(d >= s.min)) return false;
    if (s.max_open ? !(d < s.max) : !(d <= s.max)) return false;
    return true;
  };
  if (auto d = std::get_if<double>(&v)) { if (!num_ok(*d)) bad("is out of range"); }
  if (auto i = std::get_if<long>(&v)) { if (!num_ok(static_cast<double>(*i))) bad("is out of range"); }
  if (auto l = std::get_if<std::vector<double>>(&v)) {
    for (double d : *l) if (!num_ok(d)) bad("has an entry out of range");
    if (l->size() < s.list_min || l->size() > s.list_max) bad("has the wrong number of entries");
  }
  auto in_choices = [&](const std::string& x) {
    return s.choices.empty() || std::find(s.choices.begin(), s.choices.end(), x) != s.choices.end();
  };
  if (auto str = std::get_if<std::string>(&v)) { if (!in_choices(*str)) bad("is not a known choice"); }
  if (auto l = std::get_if<std::vector<std::string>>(&v)) {
    for (auto& x : *l) if (!in_choices(x)) bad("has an unknown entry '" + x + "'");
    if (l->size() < s.list_min || l->size() > s.list_max) bad("has the wrong number of entries");
  }
}

// Close names for "did you mean" hints (edit distance <= 2, or same last segment).
std::string suggestion(const ParamTable& t, const std::string& key) {
  auto dist = [](const std::string& a, const std::string& b) {
    std::vector<std::size_t> p(b.size() + 1), c(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) p[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      c[0] = i;
      for (std::size_t j = 1; j <= b.size(); ++j)
        c[j] = std::min({p[j] + 1, c[j - 1] + 1, p[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      std::swap(p, c);
    }
    return p[b.size()];
  };
  std::string best;
  std::size_t bd = 3;
  for (auto& s : t.specs()) {
    const std::size_t d = dist(s.key, key);
    if (d < bd) { bd = d; best = s.key; }
  }
  if (!best.empty()) return " Did you mean '" + best + "'?";
  // List the keys of the same section.
  const auto dot = key.rfind('.');
  const std::string section = dot == std::string::npos ? "" : key.substr(0, dot + 1);
  std::string keys;
  int n = 0;
  for (auto& s : t.specs())
    if (s.key.rfind(section, 0) == 0 && n++ < 12) keys += (keys.empty() ? "" : ", ") + s.key;
  if (keys.empty()) return " Run `fracflow check` on a scenario or see the README's parameter reference for the known keys.";
  return " Known keys here: " + keys + ".";
}

}  // namespace

std::vector<RawEntry> parse_toml_flat(std::string_view text, const std::string& source) {
  std::size_t keys = 0;
  const std::string clean = to_ascii_toml(sanitize(text, source), source, keys);
  // Checked before toml++ builds its tree (the memory and time of a huge file).
  if (keys > kMaxScenarioKeys)
    throw InputError(fmt::format("{}: the scenario has {} keys; the limit is {} (a scenario with every group pair and "
                                 "region allowed has fewer)",
                                 source, keys, kMaxScenarioKeys));
  toml::table doc;
  try {
    doc = toml::parse(clean, std::string_view(source));
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: TOML syntax error: {}", source, e.source().begin.line, e.source().begin.column,
                                 e.description()));
  }
  std::vector<RawEntry> out;
  flatten(doc, "", source, out);
  return out;
}

std::string peek_driver(std::string_view text, const std::string& source) {
  return peek_driver(parse_toml_flat(text, source), source);
}

std::string peek_driver(const std::vector<RawEntry>& entries, const std::string& source) {
  for (auto& e : entries)
    if (e.key == "driver") {
      if (auto s = std::get_if<std::string>(&e.value)) return *s;
      throw InputError(fmt::format("{}:{}: key 'driver' must be a string naming the driver", source, e.line));
    }
  return "";
}

Config build_config(const ParamTable& table, const std::string& source, const std::vector<RawEntry>& entries,
                    const std::vector<std::string>& overrides) {
  Config cfg(&table, source);
  auto apply = [&](const RawEntry& e, const std::string& where, ParamOrigin origin) {
    const ParamSpec* s = table.find(e.key);
    if (!s) throw InputError(fmt::format("{}: unknown key '{}'.{}", where, e.key, suggestion(table, e.key)));
    ParamValue v = coerce(*s, e, where);
    check_range(*s, e.key, v, where);
    cfg.set(e.key, std::move(v), std::move(origin));
  };
  for (auto& e : entries) apply(e, fmt::format("{}:{}", source, e.line), ParamOrigin{ParamOrigin::File, source, e.line});
  for (auto& o : overrides) {
    const auto eq = o.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError(fmt::format("--set '{}': expected key=value, e.g. --set dem.local_damping=0.5", o));
    std::string key = o.substr(0, eq), val = o.substr(eq + 1);
    while (!key.empty() && key.back() == ' ') key.pop_back();
    if (key.empty() || key.front() == '.' || key.back() == '.' || key.find("..") != std::string::npos)
      throw InputError(fmt::format("--set '{}': the key has an empty name between dots", o));
    // The value is read as TOML; a bare word that is not valid TOML is taken as a string.
    std::vector<RawEntry> parsed;
    try {
      parsed = parse_toml_flat("v = " + val, "--set " + key);
    } catch (const InputError&) {
      parsed = parse_toml_flat("v = \"" + val + "\"", "--set " + key);
    }
    // Exactly one plain value: `{}` gives no entry, `{a=1}` gives "v.a", "1\nw=2" two entries.
    if (parsed.size() != 1 || parsed.front().key != "v")
      throw InputError(fmt::format("--set '{}': the value must be one number, string, boolean or list, "
                                   "e.g. --set dem.local_damping=0.5 or --set dem.gravity=[0,0,-9.81]", o));
    RawEntry e = parsed.front();
    e.key = key;
    e.line = 0;
    apply(e, "--set " + key, ParamOrigin{ParamOrigin::CommandLine, "--set", 0});
  }
  // Required keys must be present.
  for (auto& s : table.specs())
    if (!s.default_value && s.key.find('*') == std::string::npos && !cfg.has(s.key))
      throw InputError(fmt::format("{}: required key '{}' is missing: {} [{}] ({})", source, s.key, s.allowed(), s.unit, s.help));
  return cfg;
}

Config load_scenario(const ParamTable& table, const std::string& path, std::string_view text,
                     const std::vector<std::string>& overrides) {
  return load_scenario(table, path, parse_toml_flat(text, path.empty() ? "<built-in default scenario>" : path),
                       overrides);
}

Config load_scenario(const ParamTable& table, const std::string& path, const std::vector<RawEntry>& entries,
                     const std::vector<std::string>& overrides) {
  const std::string source = path.empty() ? "<built-in default scenario>" : path;
  Config cfg = build_config(table, source, entries, overrides);
  if (!path.empty() && entries.empty())  // after build_config, so that a bad --set is reported as such
    throw InputError(fmt::format("{}: the scenario file sets no key (it is empty or holds only comments); write at "
                                 "least driver = \"NAME\" and the keys to change (`fracflow drivers` lists the drivers), "
                                 "or run `fracflow run` without a file for the built-in default scenario",
                                 source));
  return cfg;
}

}  // namespace ff
