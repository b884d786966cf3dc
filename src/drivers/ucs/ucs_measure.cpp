#include "drivers/ucs/ucs_measure.hpp"

#include <cmath>

namespace ff::drivers {

void CompressionGauge::init(const dem::DemSystem& sys, const dem::SampleInfo& info) {
  const auto& P = sys.particles;
  Real rmax = 0;
  for (Real r : P.radius) rmax = std::max(rmax, r);
  const int ax = info.axis;
  h0_ = sys.walls[1].point[ax] - sys.walls[0].point[ax];
  const Real z0 = sys.walls[0].point[ax];
  gauge_.clear();
  for (std::size_t i = 0; i < P.size(); ++i) {
    const Vec3 x0 = P.pos[i] - P.disp[i];
    const Real h = (x0[ax] - z0) / h0_;
    if (h < 0.25 || h > 0.75) continue;
    Real dist_to_surface;
    if (info.cylinder) dist_to_surface = 0.5 * info.width - std::hypot(x0.x(), x0.y());
    else dist_to_surface = std::min(x0.x(), info.width - x0.x());
    if (dist_to_surface < 2 * rmax) gauge_.push_back(static_cast<Index>(i));
  }
}

CompressionState CompressionGauge::measure(const dem::DemSystem& sys, const dem::SampleInfo& info) const {
  CompressionState s;
  const int ax = info.axis;
  const auto& bottom = sys.walls[0];
  const auto& top = sys.walls[1];
  const Real h = top.point[ax] - bottom.point[ax];
  s.axial_strain = (h0_ - h) / h0_;
  // Particles push the bottom platen towards -axis and the top one towards +axis.
  s.axial_stress = 0.5 * (-bottom.force[ax] + top.force[ax]) / info.area;
  const auto& P = sys.particles;
  Real sum = 0;
  for (Index i : gauge_) {
    const Vec3 x0 = P.pos[i] - P.disp[i];
    if (info.cylinder) {
      const Real r0 = std::hypot(x0.x(), x0.y());
      sum += (std::hypot(P.pos[i].x(), P.pos[i].y()) - r0) / r0;
    } else {
      const Real c = 0.5 * info.width;
      sum += (std::abs(P.pos[i].x() - c) - std::abs(x0.x() - c)) / std::abs(x0.x() - c);
    }
  }
  s.lateral_strain = gauge_.empty() ? 0 : -sum / static_cast<Real>(gauge_.size());
  s.volumetric_strain = s.axial_strain + (info.dim == 3 ? 2 : 1) * s.lateral_strain;
  return s;
}

ElasticFit fit_elastic(const std::vector<Real>& e, const std::vector<Real>& s, const std::vector<Real>& l,
                       std::size_t peak, Real lo, Real hi) {
  ElasticFit f;
  if (e.empty() || peak >= s.size()) return f;
  const Real speak = s[peak];
  Real n = 0, se = 0, ss = 0, see = 0, ses = 0, sl = 0, sel = 0;
  for (std::size_t k = 0; k <= peak; ++k) {
    if (s[k] < lo * speak || s[k] > hi * speak) continue;
    n += 1;
    se += e[k];
    ss += s[k];
    see += e[k] * e[k];
    ses += e[k] * s[k];
    sl += l[k];
    sel += e[k] * l[k];
  }
  f.points = static_cast<int>(n);
  const Real den = n * see - se * se;
  if (n < 2 || den <= 0) return f;
  f.youngs_modulus = (n * ses - se * ss) / den;
  f.poisson_ratio = -(n * sel - se * sl) / den;
  return f;
}

}  // namespace ff::drivers
