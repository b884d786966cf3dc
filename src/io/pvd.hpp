// ParaView time series (.pvd "Collection"): lists each snapshot file with its time so that
// ParaView's time slider shows physical time. Rewritten atomically after every add, so the
// series is always readable while the run goes on.
#pragma once
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

namespace ff {

class PvdSeries {
 public:
  struct Entry {
    double time = 0;
    int part = 0;
    std::string file;  // relative to the .pvd's folder
  };

  // Starts the series (writing an empty collection). With `resume`, first re-reads an existing
  // file and keeps its entries with time <= keep_until_time (a restart drops later snapshots).
  void open(const std::filesystem::path& pvd_path, bool resume = false,
            double keep_until_time = std::numeric_limits<double>::infinity());
  // Appends a snapshot (part 0) and rewrites the .pvd.
  void add(double time, const std::string& file_relative_to_pvd);
  // Appends one part of a multi-part snapshot (e.g. particles = 0, walls = 1) and rewrites the .pvd.
  void add(double time, const std::string& file_relative_to_pvd, int part);

  const std::vector<Entry>& entries() const { return entries_; }  // current entries, in order
  const std::filesystem::path& path() const { return path_; }     // the .pvd file
  bool is_open() const { return !path_.empty(); }                 // open() was called

 private:
  void write() const;
  std::filesystem::path path_;
  std::vector<Entry> entries_;
};

// Parses the DataSet entries of a .pvd text (as written by PvdSeries); `source` names it in errors.
std::vector<PvdSeries::Entry> parse_pvd(const std::string& text, const std::string& source);

}  // namespace ff
