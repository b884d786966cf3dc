#include "drivers/ucs/ucs_measure.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/log.hpp"

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
  const std::string window = fmt::format("{:g}%-{:g}% of the peak", 100 * lo, 100 * hi);
  if (e.empty() || peak >= s.size()) {
    f.reason = "the run recorded no stress-strain curve";
    return f;
  }
  const Real speak = s[peak];
  if (!(speak > 0)) {
    f.reason = "the stress never rose above zero";
    return f;
  }
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
  if (n < 2) {
    f.reason = fmt::format("{} point{} of the curve before the peak {} between {} (2 needed): the curve is sampled too "
                           "coarsely, or the run stopped long before the stress peaked",
                           f.points, f.points == 1 ? "" : "s", f.points == 1 ? "lies" : "lie", window);
    return f;
  }
  if (!(den > 0)) {
    f.reason = fmt::format("the {} points between {} all have the same axial strain", f.points, window);
    return f;
  }
  const Real E = (n * ses - se * ss) / den;
  if (!(E > 0) || !std::isfinite(E)) {
    f.reason = fmt::format("the stress does not rise with the strain between {} (slope {:.4g} Pa)", window, E);
    return f;
  }
  f.youngs_modulus = E;
  f.poisson_ratio = -(n * sel - se * sl) / den;
  return f;
}

void put_elastic_fit(nlohmann::json& j, const ElasticFit& f, const std::string& method) {
  j["youngs_modulus_Pa"] = f.ok() ? nlohmann::json(f.youngs_modulus) : nlohmann::json(nullptr);
  j["poisson_ratio"] = f.ok() ? nlohmann::json(f.poisson_ratio) : nlohmann::json(nullptr);
  j["elastic_fit"] = {{"method", method}, {"points", f.points}};
  if (f.ok()) return;
  j["elastic_fit"]["reason"] = f.reason;
  log::warn("no Young's modulus or Poisson's ratio (null in summary.json): {}", f.reason);
}

}  // namespace ff::drivers
