// The peak of a loading curve measured near equilibrium: the largest stress among the rows whose
// unbalanced-force ratio is below a threshold. A crack burst can put a one-row spike on the
// platen stress (grains thrown onto a platen, a pore at 100+ MPa) that is a dynamic transient,
// not a strength, and that does not repeat from run to run (docs/saturated.md, "Peak stress").
#pragma once
#include <cstddef>
#include <optional>
#include <span>

namespace ff::batch {

// Index of the largest stress[k] with unbalanced[k] < threshold (the first on ties); none when no
// row qualifies. The spans must have the same length.
inline std::optional<std::size_t> quasi_static_peak(std::span<const double> stress, std::span<const double> unbalanced,
                                                    double threshold) {
  std::optional<std::size_t> peak;
  for (std::size_t k = 0; k < stress.size() && k < unbalanced.size(); ++k)
    if (unbalanced[k] < threshold && (!peak || stress[k] > stress[*peak])) peak = k;
  return peak;
}

}  // namespace ff::batch
