// Measurements of a compression test: platen stress and strain, lateral strain from a
// mid-height gauge on the sample's outer shell, and the elastic constants fitted on the
// pre-peak curve. Rock-mechanics signs: compression positive (bulging gives negative lateral
// strain), volumetric strain = axial + 2 lateral (3D) or axial + lateral (2D).
#pragma once
#include <nlohmann/json.hpp>

#include <limits>
#include <string>
#include <vector>

#include "dem/dem_system.hpp"
#include "dem/sample_builder.hpp"

namespace ff::drivers {

struct CompressionState {
  Real axial_strain = 0, axial_stress = 0, lateral_strain = 0, volumetric_strain = 0;
};

class CompressionGauge {
 public:
  // Selects the gauge particles: outer shell (within two max radii of the surface) between
  // 25% and 75% of the height. Platens are walls 0 (bottom) and 1 (top) of the system.
  void init(const dem::DemSystem& sys, const dem::SampleInfo& info);
  CompressionState measure(const dem::DemSystem& sys, const dem::SampleInfo& info) const;
  Real initial_height() const { return h0_; }
  // The gauge particles, for checkpoints: on resume they are restored, never re-selected (the
  // platens have moved since, so a new selection would pick other particles).
  const std::vector<Index>& particles() const { return gauge_; }
  void restore(std::vector<Index> particles, Real h0) {
    gauge_ = std::move(particles);
    h0_ = h0;
  }

 private:
  std::vector<Index> gauge_;
  Real h0_ = 0;
};

// Young's modulus and Poisson's ratio from a least-squares line through the pre-peak points
// whose stress lies in [lo, hi] x peak (ISRM-style average modulus; default 20%-50%). Without
// a usable line (fewer than 2 points, no strain spread, no positive peak or slope) both are
// NaN and `reason` says why: summary.json then holds null, never a made-up 0.
struct ElasticFit {
  Real youngs_modulus = std::numeric_limits<Real>::quiet_NaN(), poisson_ratio = std::numeric_limits<Real>::quiet_NaN();
  int points = 0;
  std::string reason;  // empty when the fit is usable
  bool ok() const { return reason.empty(); }
};
ElasticFit fit_elastic(const std::vector<Real>& axial_strain, const std::vector<Real>& stress,
                       const std::vector<Real>& lateral_strain, std::size_t peak_index, Real lo = 0.2, Real hi = 0.5);

// youngs_modulus_Pa, poisson_ratio and the "elastic_fit" block (method, points, and the reason
// when there is no fit) of summary.json; an unusable fit also gets a warning on screen.
void put_elastic_fit(nlohmann::json& summary, const ElasticFit& fit, const std::string& method);

}  // namespace ff::drivers
