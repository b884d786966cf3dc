// Time series as CSV: one header line of column names, then one line of numbers per sample,
// each in shortest round-trip form so a resumed run can reproduce the file byte for byte.
#pragma once
#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace ff {

class CsvWriter {
 public:
  CsvWriter() = default;
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;
  CsvWriter(CsvWriter&& o) noexcept;
  CsvWriter& operator=(CsvWriter&& o) noexcept;

  // Creates (truncates) the file, with parent folders, and writes the header line.
  void open(const std::filesystem::path& path, std::vector<std::string> columns);
  // Resumes a file: checks its header equals `columns`, keeps the first `rows_to_keep` data
  // rows and drops later ones (the restarted run recomputes them). Throws ff::InputError
  // naming the file when the header differs or fewer rows exist.
  void reopen(const std::filesystem::path& path, std::vector<std::string> columns, std::size_t rows_to_keep);
  // Appends one line (values in fmt "{}" form) and flushes; throws ff::Error if the count is wrong.
  void row(std::span<const double> values);
  void row(std::initializer_list<double> values) { row(std::span<const double>(values.begin(), values.size())); }
  void close();  // flushes and closes (also done by the destructor)

  std::size_t rows() const { return rows_; }            // data rows in the file
  bool is_open() const { return f_ != nullptr; }        // between open()/reopen() and close()
  const std::vector<std::string>& columns() const { return columns_; }  // header names
  const std::filesystem::path& path() const { return path_; }           // file being written

 private:
  [[noreturn]] void fail(const char* what) const;
  std::filesystem::path path_;
  std::vector<std::string> columns_;
  std::FILE* f_ = nullptr;
  std::size_t rows_ = 0;
  std::string line_;  // reused buffer: no allocation per row once warmed up
};

// A CSV file read back: column names and one numeric vector per column.
struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> data;  // data[c][r]; non-numeric cells are NaN
  std::string source;                     // file name, for error messages

  std::size_t rows() const { return data.empty() ? 0 : data.front().size(); }  // data rows
  bool has(std::string_view name) const;                                      // column exists
  // The column called `name`; throws ff::InputError listing the columns when absent.
  const std::vector<double>& column(std::string_view name) const;
};

// Reads a comma-separated file with a header line; lines starting with '#' and blank lines
// are skipped. Throws ff::InputError naming file and line on ragged rows or a missing file.
CsvTable read_csv(const std::filesystem::path& path);
// Same, from text already in memory; `source` names it in errors.
CsvTable parse_csv(std::string_view text, const std::string& source);
// The whole of `cell` as a number (a leading '+' allowed); NaN when it is not one.
double to_number(std::string_view cell);

}  // namespace ff
