#include "io/csv.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>

#include "core/error.hpp"
#include "io/atomic_file.hpp"

namespace ff {

namespace {

std::string join(const std::vector<std::string>& cols) {
  std::string h;
  for (std::size_t i = 0; i < cols.size(); ++i) h += (i ? "," : "") + cols[i];
  return h;
}

void check_columns(const std::filesystem::path& path, const std::vector<std::string>& cols) {
  if (cols.empty()) throw Error(fmt::format("internal: CSV '{}' opened without columns", path.string()));
  for (auto& c : cols)
    if (c.empty() || c.find_first_of(",\n\r\"") != std::string::npos)
      throw Error(fmt::format("internal: CSV '{}': column name '{}' is empty or holds a comma, quote or newline", path.string(), c));
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  for (;;) {
    const auto comma = line.find(',', start);
    out.push_back(trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) return out;
    start = comma + 1;
  }
}

bool skipped(std::string_view line) {
  const auto t = trim(line);
  return t.empty() || t.front() == '#';
}

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("cannot read '{}': no such file or not readable", path.string()));
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

double to_number(std::string_view cell) {
  if (!cell.empty() && cell.front() == '+') cell.remove_prefix(1);  // from_chars rejects a leading '+'
  double v = std::numeric_limits<double>::quiet_NaN();
  auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
  if (ec != std::errc() || end != cell.data() + cell.size()) return std::numeric_limits<double>::quiet_NaN();
  return v;
}

// ---------------------------------------------------------------- CsvWriter

CsvWriter::~CsvWriter() { close(); }

CsvWriter::CsvWriter(CsvWriter&& o) noexcept
    : path_(std::move(o.path_)), columns_(std::move(o.columns_)), f_(o.f_), rows_(o.rows_), line_(std::move(o.line_)) {
  o.f_ = nullptr;
}

CsvWriter& CsvWriter::operator=(CsvWriter&& o) noexcept {
  if (this != &o) {
    close();
    path_ = std::move(o.path_);
    columns_ = std::move(o.columns_);
    f_ = o.f_;
    rows_ = o.rows_;
    line_ = std::move(o.line_);
    o.f_ = nullptr;
  }
  return *this;
}

void CsvWriter::fail(const char* what) const {
  throw Error(fmt::format("cannot write CSV '{}': {} ({})", path_.string(), what, std::strerror(errno)));
}

void CsvWriter::close() {
  if (f_) std::fclose(f_);
  f_ = nullptr;
}

void CsvWriter::open(const std::filesystem::path& path, std::vector<std::string> columns) {
  close();
  check_columns(path, columns);
  write_file_atomic(path, join(columns) + "\n");  // creates folders, replaces an old file whole
  path_ = path;
  columns_ = std::move(columns);
  rows_ = 0;
  f_ = std::fopen(path_.c_str(), "ab");
  if (!f_) fail("cannot open for appending");
}

void CsvWriter::reopen(const std::filesystem::path& path, std::vector<std::string> columns, std::size_t rows_to_keep) {
  close();
  check_columns(path, columns);
  if (!std::filesystem::exists(path)) {
    if (rows_to_keep > 0)
      throw InputError(fmt::format("cannot resume '{}': the file is missing but the checkpoint expects {} rows in it",
                                   path.string(), rows_to_keep));
    open(path, std::move(columns));
    return;
  }
  const std::string text = slurp(path), header = join(columns);
  std::string kept;
  bool have_header = false;
  std::size_t kept_rows = 0, line_no = 0, pos = 0;
  while (pos < text.size() && !(have_header && kept_rows == rows_to_keep)) {
    const auto nl = text.find('\n', pos);
    const std::string_view line(text.data() + pos, (nl == std::string::npos ? text.size() : nl) - pos);
    pos = nl == std::string::npos ? text.size() : nl + 1;
    ++line_no;
    if (skipped(line)) {
      if (!have_header) kept.append(line).push_back('\n');
      continue;
    }
    if (!have_header) {
      if (trim(line) != header)
        throw InputError(fmt::format("cannot resume '{}': its header line '{}' differs from this run's '{}' "
                                     "(was the file written by another scenario or version?)",
                                     path.string(), trim(line), header));
      have_header = true;
      kept.append(header).push_back('\n');
      continue;
    }
    if (split(line).size() != columns.size() || nl == std::string::npos)
      throw InputError(fmt::format("cannot resume '{}': line {} is incomplete (was the run killed while writing it?)",
                                   path.string(), line_no));
    kept.append(line).push_back('\n');
    ++kept_rows;
  }
  if (!have_header) throw InputError(fmt::format("cannot resume '{}': the file has no header line", path.string()));
  if (kept_rows < rows_to_keep)
    throw InputError(fmt::format("cannot resume '{}': it holds {} data rows but the checkpoint expects {}", path.string(),
                                 kept_rows, rows_to_keep));
  write_file_atomic(path, kept);
  path_ = path;
  columns_ = std::move(columns);
  rows_ = kept_rows;
  f_ = std::fopen(path_.c_str(), "ab");
  if (!f_) fail("cannot open for appending");
}

void CsvWriter::row(std::span<const double> values) {
  if (!f_) throw Error(fmt::format("internal: CSV row written to '{}' before open()", path_.string()));
  if (values.size() != columns_.size())
    throw Error(fmt::format("internal: CSV '{}': row has {} values but the header has {} columns", path_.string(),
                            values.size(), columns_.size()));
  line_.clear();
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i) line_.push_back(',');
    fmt::format_to(std::back_inserter(line_), "{}", values[i]);  // shortest round-trip form
  }
  line_.push_back('\n');
  if (std::fwrite(line_.data(), 1, line_.size(), f_) != line_.size() || std::fflush(f_) != 0) fail("write failed (disk full?)");
  ++rows_;
}

// ---------------------------------------------------------------- reading

bool CsvTable::has(std::string_view name) const {
  for (auto& c : columns)
    if (c == name) return true;
  return false;
}

const std::vector<double>& CsvTable::column(std::string_view name) const {
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (columns[i] == name) return data[i];
  std::string known;
  for (auto& c : columns) known += (known.empty() ? "" : ", ") + c;
  throw InputError(fmt::format("'{}' has no column '{}' (columns: {})", source, name, known));
}

CsvTable parse_csv(std::string_view text, const std::string& source) {
  CsvTable t;
  t.source = source;
  bool have_header = false;
  std::size_t line_no = 0, pos = 0;
  while (pos < text.size()) {
    const auto nl = text.find('\n', pos);
    const std::string_view line = text.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos);
    pos = nl == std::string_view::npos ? text.size() : nl + 1;
    ++line_no;
    if (skipped(line)) continue;
    const auto cells = split(line);
    if (!have_header) {
      for (auto c : cells) {
        if (c.size() >= 2 && c.front() == '"' && c.back() == '"') c = c.substr(1, c.size() - 2);
        t.columns.emplace_back(c);
      }
      t.data.resize(t.columns.size());
      have_header = true;
      continue;
    }
    if (cells.size() != t.columns.size())
      throw InputError(fmt::format("{}:{}: {} fields, but the header has {} columns", source, line_no, cells.size(),
                                   t.columns.size()));
    for (std::size_t c = 0; c < cells.size(); ++c) t.data[c].push_back(to_number(cells[c]));
  }
  if (!have_header) throw InputError(fmt::format("'{}' has no header line (only comments or nothing)", source));
  return t;
}

CsvTable read_csv(const std::filesystem::path& path) { return parse_csv(slurp(path), path.string()); }

}  // namespace ff
