// Verlet neighbour list with linked cells (src/dem/neighbor_list.*) against brute force.
// Reference: Allen & Tildesley (1987), Computer Simulation of Liquids, sec. 5.3 (Verlet list with a
// skin, rebuilt when a particle has moved more than skin/2) and 5.3.2 (linked cells). The list
// must equal the O(N^2) set {i < j : |x_j - x_i| < r_i + r_j + skin} exactly, sorted by (i, j).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <map>
#include <utility>
#include <vector>

#include "core/rng.hpp"
#include "dem/dem_system.hpp"
#include "single_threaded.hpp"
#include "dem/neighbor_list.hpp"

using namespace ff;
using namespace ff::dem;

namespace {

using Pairs = std::vector<std::pair<Index, Index>>;

// The same predicate as the list (squared distances), so no rounding ambiguity at the cut-off.
Pairs brute_force(const std::vector<Vec3>& x, const std::vector<Real>& r, Real skin) {
  Pairs p;
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::size_t j = i + 1; j < x.size(); ++j) {
      const Real cut = r[i] + r[j] + skin;
      if ((x[j] - x[i]).squaredNorm() < cut * cut) p.emplace_back(static_cast<Index>(i), static_cast<Index>(j));
    }
  return p;
}

Pairs listed(const NeighborList& nl) {
  Pairs p;
  for (std::size_t k = 0; k < nl.size(); ++k) p.emplace_back(nl.first()[k], nl.second()[k]);
  return p;
}

// Random polydisperse particles in a box (z = 0 in 2D); radii in [rmin, rmax].
void random_particles(Rng& g, int dim, std::size_t n, Real box, Real rmin, Real rmax, std::vector<Vec3>& x,
                      std::vector<Real>& r) {
  x.resize(n);
  r.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = Vec3(g.uniform(0, box), g.uniform(0, box), dim == 3 ? g.uniform(0, box) : 0.0);
    r[i] = g.uniform(rmin, rmax);
  }
}

// Every particle's adjacency lists its pairs in increasing pair order, with the right end flag.
void check_adjacency(const NeighborList& nl, std::size_t n) {
  const auto off = nl.adjacency_offsets();
  const auto adj = nl.adjacency();
  ASSERT_EQ(off.size(), n + 1);
  ASSERT_EQ(static_cast<std::size_t>(off[n]), 2 * nl.size());
  for (std::size_t i = 0; i < n; ++i) {
    for (std::int64_t k = off[i]; k < off[i + 1]; ++k) {
      const std::int64_t p = adj[k] >> 1;
      const bool second = adj[k] & 1;
      ASSERT_EQ(static_cast<std::size_t>(second ? nl.second()[p] : nl.first()[p]), i);
      if (k > off[i]) {
        ASSERT_LT(adj[k - 1] >> 1, p);
      }
    }
  }
}

}  // namespace

TEST(NeighborList, EqualsBruteForce3DAnd2D) {
  // Polydisperse (radius ratio 5) random particles, 3D and 2D, built on 1 and 3 threads (the
  // count and fill passes are parallel). Exact equality, sorted (i, j).
  Rng g(11);
  for (int dim : {3, 2}) {
    std::vector<Vec3> x;
    std::vector<Real> r;
    const std::size_t n = dim == 3 ? 800 : 500;
    random_particles(g, dim, n, dim == 3 ? 0.012 : 0.03, 0.2e-3, 1.0e-3, x, r);
    const Real skin = 0.3e-3;
    const Pairs want = brute_force(x, r, skin);
    EXPECT_GT(want.size(), n);  // a meaningful number of pairs
    for (int threads : {1, 3}) {
      omp_set_num_threads(threads);
      NeighborList nl;
      nl.set_parallel_min(0);  // every loop parallel, however small the system
      EXPECT_EQ(nl.build(x, r, skin), want.size());
      const Pairs have = listed(nl);
      EXPECT_EQ(have, want) << "dim " << dim << ", " << threads << " threads";  // brute force is (i, j) ordered
      EXPECT_TRUE(std::is_sorted(have.begin(), have.end()));
      check_adjacency(nl, n);
    }
  }
  omp_set_num_threads(1);
}

TEST(NeighborList, EqualsBruteForceWithOutlierAndEdgeCases) {
  // A particle flung far away makes the grid coarser (cells are enlarged to keep ~2 per particle);
  // the list must stay exact. Also: empty input, one particle, coincident centres.
  Rng g(12);
  std::vector<Vec3> x;
  std::vector<Real> r;
  random_particles(g, 3, 400, 0.015, 0.3e-3, 0.6e-3, x, r);
  x[17] = Vec3(50.0, -30.0, 10.0);  // far outlier
  x[18] = x[19];                    // coincident pair (listed: distance 0 < cut)
  NeighborList nl;
  nl.build(x, r, 0.1e-3);
  EXPECT_EQ(listed(nl), brute_force(x, r, 0.1e-3));
  check_adjacency(nl, x.size());
  std::vector<Vec3> none;
  std::vector<Real> rnone;
  EXPECT_EQ(nl.build(none, rnone, 0.1), 0u);
  std::vector<Vec3> one{Vec3(1, 2, 3)};
  std::vector<Real> rone{0.5};
  EXPECT_EQ(nl.build(one, rone, 0.1), 0u);
  check_adjacency(nl, 1);
}

TEST(NeighborList, NoContactMissedBetweenRebuilds) {
  // Random walk of all particles; as long as needs_rebuild() is false (no displacement above
  // skin/2 since the build) every pair in contact (|dx| < ri + rj) must already be listed
  // (Allen & Tildesley sec. 5.3). Rebuild when asked, 60 moves in all.
  Rng g(13);
  std::vector<Vec3> x;
  std::vector<Real> r;
  random_particles(g, 3, 300, 0.012, 0.4e-3, 0.8e-3, x, r);
  const Real skin = 0.2e-3;
  NeighborList nl;
  nl.build(x, r, skin);
  int rebuilds = 0;
  for (int move = 0; move < 60; ++move) {
    for (auto& p : x) p += 0.03e-3 * Vec3(g.normal(), g.normal(), g.normal());
    if (nl.needs_rebuild(x)) {
      nl.build(x, r, skin);
      ++rebuilds;
    }
    const Pairs have = listed(nl);
    for (const auto& pr : brute_force(x, r, 0.0))
      ASSERT_TRUE(std::binary_search(have.begin(), have.end(), pr)) << "contact " << pr.first << "-" << pr.second
                                                                   << " missed at move " << move;
  }
  EXPECT_GT(rebuilds, 2);
}

TEST(NeighborList, NeedsRebuildAtHalfSkin) {
  // Rebuild when max displacement (+ wall travel) exceeds skin/2 (Allen & Tildesley sec. 5.3).
  Rng g(14);
  std::vector<Vec3> x;
  std::vector<Real> r;
  random_particles(g, 3, 50, 0.01, 0.5e-3, 1e-3, x, r);
  const Real skin = 0.4e-3;
  NeighborList nl;
  nl.build(x, r, skin);
  EXPECT_FALSE(nl.needs_rebuild(x));
  const Vec3 dir = Vec3(1, -1, 2).normalized();
  std::vector<Vec3> y = x;
  y[23] += 0.49 * skin * dir;
  EXPECT_FALSE(nl.needs_rebuild(y));
  EXPECT_TRUE(nl.needs_rebuild(y, 0.02 * skin));  // wall travel counts too
  y[23] = x[23] + 0.51 * skin * dir;
  EXPECT_TRUE(nl.needs_rebuild(y));
  y.push_back(Vec3::Zero());
  EXPECT_TRUE(nl.needs_rebuild(y));  // particle count changed
}

TEST(NeighborList, CarryOverKeepsHistoryOfSurvivingPairs) {
  // Pairs present before and after a rebuild keep their state; new pairs get `fresh`.
  Rng g(15);
  std::vector<Vec3> x;
  std::vector<Real> r;
  random_particles(g, 3, 300, 0.012, 0.4e-3, 0.8e-3, x, r);
  const Real skin = 0.3e-3;
  NeighborList nl;
  nl.build(x, r, skin);
  std::vector<Index> oi(nl.first().begin(), nl.first().end()), oj(nl.second().begin(), nl.second().end());
  std::vector<Real> old_state(nl.size());
  std::map<std::pair<Index, Index>, Real> by_pair;
  for (std::size_t k = 0; k < nl.size(); ++k) {
    old_state[k] = g.uniform(1, 2);
    by_pair[{oi[k], oj[k]}] = old_state[k];
  }
  for (auto& p : x) p += 0.3e-3 * Vec3(g.normal(), g.normal(), g.normal());
  nl.build(x, r, skin);
  std::vector<Real> new_state;
  NeighborList::carry_over<Real>(oi, oj, old_state, nl.first(), nl.second(), new_state, -1.0);
  ASSERT_EQ(new_state.size(), nl.size());
  int kept = 0, fresh = 0;
  for (std::size_t k = 0; k < nl.size(); ++k) {
    const auto it = by_pair.find({nl.first()[k], nl.second()[k]});
    if (it != by_pair.end()) {
      EXPECT_EQ(new_state[k], it->second);
      ++kept;
    } else {
      EXPECT_EQ(new_state[k], -1.0);
      ++fresh;
    }
  }
  EXPECT_GT(kept, 100);
  EXPECT_GT(fresh, 10);
}

TEST(NeighborList, DemSystemRebuildKeepsContactShearForce) {
  // In the engine: a sheared contact keeps its stored shear force through a forced rebuild
  // (history carried by pair (i, j)), and a new particle does not disturb it.
  DemSystem s;
  s.settings.dim = 3;
  s.settings.dt = 1e-8;
  s.settings.local_damping = 0;
  s.settings.skin = 0.2e-3;
  s.materials.group_names = {"matrix"};
  s.materials.density = {2500};
  s.materials.set_bond_law<NoBond>();
  s.materials.contact_params<LinearContact>().resize(1);
  s.particles.resize(3);
  s.particles.radius = {1e-3, 1e-3, 1e-3};
  s.particles.pos = {Vec3(0.02, 0, 0), Vec3(0, 0, 0), Vec3(1.999e-3, 0, 0)};  // pair (1, 2) touches
  for (std::size_t i = 0; i < 3; ++i) s.particles.set_mass_from_density(i, 2500, 3);
  s.particles.vel[2] = Vec3(0, 0.05, 0);
  s.initialise();
  s.step();
  ASSERT_EQ(s.neighbors().size(), 1u);
  const Vec3 fs = s.contact_state()[0].fs;
  EXPECT_GT(fs.norm(), 0.0);
  s.particles.pos[0] = Vec3(1e-3, 1.8e-3, 0);  // particle 0 joins: pairs (0,1), (0,2), (1,2)
  s.rebuild_neighbors();
  ASSERT_EQ(s.neighbors().size(), 3u);
  EXPECT_EQ(s.neighbors().first()[2], 1);
  EXPECT_EQ(s.contact_state()[2].fs, fs);
  EXPECT_EQ(s.contact_state()[0].fs.norm() + s.contact_state()[1].fs.norm(), 0.0);
}
