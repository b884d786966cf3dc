#include "io/pvd.hpp"

#include <fmt/format.h>

#include <charconv>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "io/atomic_file.hpp"

namespace ff {

namespace {

std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string unescape(std::string_view s) {
  static const std::pair<std::string_view, char> kEntities[] = {{"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}};
  std::string o;
  for (std::size_t i = 0; i < s.size();) {
    bool done = false;
    for (auto& [ent, c] : kEntities)
      if (s.substr(i, ent.size()) == ent) {
        o += c;
        i += ent.size();
        done = true;
        break;
      }
    if (!done) o += s[i++];
  }
  return o;
}

// Reads attribute `name` of one element into `out`; false when absent.
bool attribute(std::string_view element, std::string_view name, std::string& out) {
  for (std::size_t p = element.find(name); p != std::string_view::npos; p = element.find(name, p + 1)) {
    const bool starts = p > 0 && (element[p - 1] == ' ' || element[p - 1] == '\t' || element[p - 1] == '\n');
    std::size_t q = p + name.size();
    while (q < element.size() && element[q] == ' ') ++q;
    if (!starts || q >= element.size() || element[q] != '=') continue;
    ++q;
    while (q < element.size() && element[q] == ' ') ++q;
    if (q >= element.size() || (element[q] != '"' && element[q] != '\'')) return false;
    const char quote = element[q];
    const auto end = element.find(quote, q + 1);
    if (end == std::string_view::npos) return false;
    out = unescape(element.substr(q + 1, end - q - 1));
    return true;
  }
  return false;
}

}  // namespace

std::vector<PvdSeries::Entry> parse_pvd(const std::string& text, const std::string& source) {
  std::vector<PvdSeries::Entry> out;
  for (std::size_t p = text.find("<DataSet"); p != std::string::npos; p = text.find("<DataSet", p + 1)) {
    const auto end = text.find('>', p);
    if (end == std::string::npos) throw InputError(fmt::format("'{}': unterminated <DataSet element", source));
    const std::string_view el(text.data() + p, end - p);
    std::string t, part, file;
    PvdSeries::Entry e;
    if (!attribute(el, "timestep", t) || !attribute(el, "file", file))
      throw InputError(fmt::format("'{}': a <DataSet> element lacks its timestep or file attribute", source));
    const auto [tp, tec] = std::from_chars(t.data(), t.data() + t.size(), e.time);
    if (tec != std::errc() || tp != t.data() + t.size())
      throw InputError(fmt::format("'{}': timestep \"{}\" is not a number", source, t));
    if (attribute(el, "part", part)) {
      const auto [pp, pec] = std::from_chars(part.data(), part.data() + part.size(), e.part);
      if (pec != std::errc() || pp != part.data() + part.size())
        throw InputError(fmt::format("'{}': part \"{}\" is not an integer", source, part));
    }
    e.file = std::move(file);
    out.push_back(std::move(e));
  }
  return out;
}

void PvdSeries::open(const std::filesystem::path& pvd_path, bool resume, double keep_until_time) {
  path_ = pvd_path;
  entries_.clear();
  if (resume && std::filesystem::exists(path_)) {
    std::ifstream in(path_, std::ios::binary);
    if (!in) throw InputError(fmt::format("cannot resume '{}': not readable", path_.string()));
    std::ostringstream ss;
    ss << in.rdbuf();
    for (auto& e : parse_pvd(ss.str(), path_.string()))
      if (e.time <= keep_until_time) entries_.push_back(std::move(e));
  }
  write();
}

void PvdSeries::add(double time, const std::string& file_relative_to_pvd) { add(time, file_relative_to_pvd, 0); }

void PvdSeries::add(double time, const std::string& file_relative_to_pvd, int part) {
  if (path_.empty()) throw Error("internal: PvdSeries::add before open");
  entries_.push_back({time, part, file_relative_to_pvd});
  write();
}

void PvdSeries::write() const {
  std::string o = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n";
  for (auto& e : entries_)  // times in shortest round-trip form: a resume compares them exactly
    o += fmt::format("    <DataSet timestep=\"{}\" group=\"\" part=\"{}\" file=\"{}\"/>\n", e.time, e.part, escape(e.file));
  o += "  </Collection>\n</VTKFile>\n";
  write_file_atomic(path_, o);
}

}  // namespace ff
