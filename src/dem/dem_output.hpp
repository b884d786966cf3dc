// ParaView output of a DEM system: particles, intact bonds, contact-force network, cracks and
// walls, one .vtp each per snapshot under vtk/, each kind indexed by its own .pvd series.
#pragma once
#include <filesystem>

#include "dem/dem_system.hpp"
#include "io/pvd.hpp"

namespace ff::dem {

class DemVtkWriter {
 public:
  // Opens the series under `dir` (created). With `resume`, keeps the snapshots up to `time`.
  // `membrane`: also a series of the flexible membrane's triangles (membrane.pvd).
  void open(const std::filesystem::path& dir, bool resume = false, double time = 0, bool membrane = false);
  // Particles from index n on are a boundary (a particle membrane): they are written with the
  // particles (their own group) and bonds, but their contacts stay out of the contact network.
  void set_sample_particles(std::size_t n) { sample_particles_ = n; }
  // Writes snapshot number `index` at the system's current time.
  void write(const DemSystem& sys, long index, Real wall_extent);
  long snapshots() const { return static_cast<long>(particles_.entries().size()); }

 private:
  std::filesystem::path dir_;
  PvdSeries particles_, bonds_, contacts_, cracks_, walls_, membrane_;
  bool with_membrane_ = false;
  std::size_t sample_particles_ = static_cast<std::size_t>(-1);
};

// Writes all crack events in [from, end) to `csv` (appending; header written when from == 0).
void append_cracks_csv(const std::filesystem::path& csv, const CrackLog& log, const Materials& mat, std::size_t from);

}  // namespace ff::dem
