#include "dem/reorder_particles.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <numeric>

#include "core/error.hpp"

namespace ff::dem {

namespace {
// A contact seen from its other end: the shear force on B becomes the shear force on A's side.
ContactState swap_ends(const ContactState& s) {
  ContactState t = s;
  t.fs = -s.fs;
  return t;
}
// A pair's last loads seen from its other end (force on the second particle, moments swapped).
PairLoad swap_ends(const PairLoad& l) { return PairLoad{-l.f, l.mB, l.mA}; }
}  // namespace

void reorder_particles(DemSystem& sys, const std::vector<Index>& order) {
  const std::size_t n = sys.particles.size();
  if (order.size() != n) throw Error(fmt::format("reorder_particles: {} indices for {} particles", order.size(), n));
  std::vector<Index> new_of_old(n, -1);
  for (std::size_t k = 0; k < n; ++k) {
    const Index o = order[k];
    if (o < 0 || static_cast<std::size_t>(o) >= n || new_of_old[o] >= 0)
      throw Error(fmt::format("reorder_particles: the order is not a permutation of 0..{} (entry {} = {})", n - 1, k, o));
    new_of_old[o] = static_cast<Index>(k);
  }
  sys.particles.permute(order);
  // Bonds: same bonds in the same order, ends renumbered.
  for (auto* e : {&sys.bonds.i, &sys.bonds.j})
    for (auto& x : *e) x = new_of_old[x];
  const std::vector<PairLoad> bond_loads = sys.bonds.loads();  // per bond: order unchanged
  sys.bonds.build_adjacency(n);
  sys.bonds.loads() = bond_loads;
  // Neighbour pairs: renumbered, (smaller, larger), sorted by (i, j) as a build leaves them.
  auto& nl = sys.nl_;
  const std::size_t np = nl.size();
  std::vector<Index> pi(np), pj(np);
  std::vector<std::uint8_t> swapped(np);
  for (std::size_t p = 0; p < np; ++p) {
    const Index a = new_of_old[nl.pair_i()[p]], b = new_of_old[nl.pair_j()[p]];
    swapped[p] = a > b;
    pi[p] = std::min(a, b);
    pj[p] = std::max(a, b);
  }
  std::vector<std::size_t> perm(np);
  std::iota(perm.begin(), perm.end(), std::size_t{0});
  std::sort(perm.begin(), perm.end(), [&](std::size_t x, std::size_t y) {
    return pi[x] < pi[y] || (pi[x] == pi[y] && pj[x] < pj[y]);
  });
  const std::vector<ContactState> cs = sys.cstate_;
  const std::vector<PairLoad> pl = sys.pload_;
  for (std::size_t q = 0; q < np; ++q) {
    const std::size_t p = perm[q];
    nl.pair_i()[q] = pi[p];
    nl.pair_j()[q] = pj[p];
    sys.cstate_[q] = swapped[p] ? swap_ends(cs[p]) : cs[p];
    if (p < pl.size()) sys.pload_[q] = swapped[p] ? swap_ends(pl[p]) : pl[p];
  }
  auto& ref = nl.reference_positions();
  if (ref.size() == n) {
    const std::vector<Vec3> old_ref = ref;
    for (std::size_t k = 0; k < n; ++k) ref[k] = old_ref[order[k]];
  }
  nl.build_adjacency(n);
  // Wall candidates: renumbered and sorted by particle with their history and last loads.
  for (auto& wc : sys.wall_contacts_) {
    const std::size_t nc = wc.particle.size();
    std::vector<std::size_t> o(nc);
    std::iota(o.begin(), o.end(), std::size_t{0});
    std::sort(o.begin(), o.end(), [&](std::size_t x, std::size_t y) {
      return new_of_old[wc.particle[x]] < new_of_old[wc.particle[y]];
    });
    const auto p = wc.particle;
    const auto st = wc.state;
    const auto ld = wc.load;
    for (std::size_t c = 0; c < nc; ++c) {
      wc.particle[c] = new_of_old[p[o[c]]];
      if (c < st.size()) wc.state[c] = st[o[c]];
      if (c < ld.size()) wc.load[c] = ld[o[c]];
    }
  }
  for (const auto& b : sys.boundaries_) b->reorder(new_of_old);
}

}  // namespace ff::dem
