// The peak of a loading curve measured near equilibrium: the largest stress among the rows whose
// unbalanced-force ratio is below a threshold. A crack burst can put a one-row spike on the
// platen stress (grains thrown onto a platen, a pore at 100+ MPa) that is a dynamic transient,
// not a strength, and that does not repeat from run to run (docs/saturated.md, "Peak stress").
#pragma once
#include <cstddef>
#include <optional>
#include <span>
#include <string_view>

#include "io/csv.hpp"

namespace ff::drivers {

// Index of the largest stress[k] with unbalanced[k] < threshold (the first on ties); none when no
// row qualifies. The spans must have the same length.
inline std::optional<std::size_t> quasi_static_peak(std::span<const double> stress, std::span<const double> unbalanced,
                                                    double threshold) {
  std::optional<std::size_t> peak;
  for (std::size_t k = 0; k < stress.size() && k < unbalanced.size(); ++k)
    if (unbalanced[k] < threshold && (!peak || stress[k] > stress[*peak])) peak = k;
  return peak;
}

// Below this unbalanced-force ratio a row of a loading curve counts as near equilibrium.
constexpr double kQuasiStaticUnbalance = 0.1;

// The quasi-static peak of a series.csv read back (its stress column, `axial_strain` and
// `unbalanced_force_ratio`): row, stress and strain; none without such a row.
struct QuasiStaticPeak {
  std::size_t row = 0;
  double stress = 0, strain = 0;
};
inline std::optional<QuasiStaticPeak> quasi_static_peak(const CsvTable& t, std::string_view stress_column) {
  const auto& s = t.column(stress_column);
  const auto k = quasi_static_peak(s, t.column("unbalanced_force_ratio"), kQuasiStaticUnbalance);
  if (!k) return std::nullopt;
  return QuasiStaticPeak{*k, s[*k], t.column("axial_strain")[*k]};
}

// The stop rule's peak of a loading curve, row by row: the largest stress among the rows that count
// (near equilibrium where the curve has an unbalanced-force ratio; every row otherwise), and whether a
// later row has fallen below a fraction of it. The peak must lie min_row rows into the loading: the
// platens' first rows are start-up noise.
struct StopPeak {
  double stress = 0, strain = 0;
  long row = -1;
  // counts: the row may be the peak (its unbalanced-force ratio below kQuasiStaticUnbalance).
  void add(long r, double s, double e, bool counts) {
    if (counts && s > stress) {
      stress = s;
      strain = e;
      row = r;
    }
  }
  bool fallen(double s, double e, double fraction, long min_row = 10) const {
    return stress > 0 && row >= min_row && e > strain && s < fraction * stress;
  }
};

}  // namespace ff::drivers
