// Pore network construction: pore void volumes, channels, apertures B1/B2 (seed 004 App. B),
// numbering independent of storage order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "core/error.hpp"
#include "packings.hpp"
#include "porenet/network.hpp"

using namespace ff;
using namespace ff::porenet;

TEST(PorenetNetwork, ThreeTouchingDiscsVoid) {
  // Equilateral triangle of side 2 with unit discs: void = sqrt(3) - pi/2 per unit depth (exact).
  std::vector<Real> x{0, 2, 1}, y{0, 0, std::sqrt(3.0)}, r{1, 1, 1};
  NetworkParams prm;
  prm.thickness = 0.5;
  const Network2D net = build_network_2d({x, y, r, {}}, {}, prm);
  ASSERT_EQ(net.n_pores(), 1);
  EXPECT_EQ(net.n_channels(), 0);
  EXPECT_NEAR(net.pore_area[0], std::sqrt(3.0), 1e-14);
  EXPECT_NEAR(net.pore_void[0], 0.5 * (std::sqrt(3.0) - kPi / 2), 1e-14);
  EXPECT_EQ(net.pore_hull[0], 1);
}

TEST(PorenetNetwork, RhombusChannelAperturesB1B2) {
  // Two triangles sharing the edge (0,0)-(2,0); centroids (1, +-0.5): L = 1, omega = 90°.
  std::vector<Real> x{0, 2, 1, 1}, y{0, 0, 1.5, -1.5}, r{0.5, 0.5, 0.5, 0.5};
  NetworkParams prm;
  prm.b2_gamma = 0.8;
  prm.thickness = 2.0;
  Network2D net = build_network_2d({x, y, r, {}}, {}, prm);
  ASSERT_EQ(net.n_pores(), 2);
  ASSERT_EQ(net.n_channels(), 1);
  EXPECT_EQ(net.ch_kind[0], ChannelKind::T2T);
  EXPECT_NEAR(net.ch_length[0], 1.0, 1e-14);
  EXPECT_NEAR(net.ch_sin_omega[0], 1.0, 1e-14);
  EXPECT_NEAR(net.ch_aperture[0], 0.8 * 1.0, 1e-14);  // B2 with the free gap 2 - 0.5 - 0.5
  EXPECT_NEAR(net.ch_cond[0], std::pow(0.8, 3) * 2.0 / 12.0, 1e-14);
  prm.b2_edge = B2Edge::Centre;
  net = build_network_2d({x, y, r, {}}, {}, prm);
  EXPECT_NEAR(net.ch_aperture[0], 0.8 * 2.0, 1e-14);  // B2 literal: centre-to-centre edge
  // A bond along the edge makes it an S2S channel with the B1 aperture.
  PairList pairs;
  pairs.add(1, 0, PairState::Bond, 2e6, 0);
  net = build_network_2d({x, y, r, {}}, pairs, prm);
  EXPECT_EQ(net.ch_kind[0], ChannelKind::S2S);
  const Real hb1 = prm.b1_beta * (prm.b1_h_inf + (prm.b1_h0 - prm.b1_h_inf) * std::exp(-1.5e-7 * 2e6));
  EXPECT_NEAR(net.ch_aperture[0], hb1, 1e-20);
  // Breaking the bond: the aperture follows its opening.
  pairs.state[0] = PairState::BrokenBond;
  pairs.sigma_n[0] = 0;
  pairs.opening[0] = 3e-5;
  update_network_2d(net, {x, y, r, {}}, pairs);
  EXPECT_NEAR(net.ch_aperture[0], prm.b1_beta * prm.b1_h0 + 3e-5, 1e-20);
  EXPECT_EQ(net.unmatched_pairs, 0);
}

TEST(PorenetNetwork, NumberingIndependentOfStorageOrder) {
  auto s = test_packings::hex_packing(12, 10, 1.0, 0.4, 0.1, 0.15);
  const Network2D a = build_network_2d(s.view(), {});
  // Reverse the storage order, keep the global ids.
  test_packings::Discs t;
  const std::size_t n = s.x.size();
  for (std::size_t k = 0; k < n; ++k) {
    t.x.push_back(s.x[n - 1 - k]);
    t.y.push_back(s.y[n - 1 - k]);
    t.r.push_back(s.r[n - 1 - k]);
    t.gid.push_back(s.gid[n - 1 - k]);
  }
  const Network2D b = build_network_2d(t.view(), {});
  ASSERT_EQ(a.n_pores(), b.n_pores());
  ASSERT_EQ(a.n_channels(), b.n_channels());
  for (Index k = 0; k < a.n_pores(); ++k) {
    for (int c = 0; c < 3; ++c) EXPECT_EQ(s.gid[a.pore_v[3 * k + c]], t.gid[b.pore_v[3 * k + c]]);
    EXPECT_EQ(a.pore_void[k], b.pore_void[k]);
  }
  for (Index c = 0; c < a.n_channels(); ++c) {
    EXPECT_EQ(a.ch_pore[2 * c], b.ch_pore[2 * c]);
    EXPECT_EQ(a.ch_pore[2 * c + 1], b.ch_pore[2 * c + 1]);
    EXPECT_EQ(a.ch_cond[c], b.ch_cond[c]);
  }
  // Euler: triangles = 2 n - 2 - hull vertices; interior edges = 3 T / 2 - hull edges / 2.
  Index hull_edges = 0;
  for (Index k = 0; k < a.n_pores(); ++k) hull_edges += 3 - (a.pc_start[k + 1] - a.pc_start[k]);
  EXPECT_EQ(a.n_pores(), 2 * static_cast<Index>(n) - 2 - hull_edges);
  // Sum of the triangle areas = area of the convex hull; voids are positive and below the areas.
  for (Index k = 0; k < a.n_pores(); ++k) {
    EXPECT_GT(a.pore_void[k], 0);
    EXPECT_LT(a.pore_void[k], a.pore_cell[k]);
  }
}

TEST(PorenetNetwork, BadInputIsRefused) {
  std::vector<Real> x{0, 1, 0}, y{0, 0, 1}, r{0.1, -0.1, 0.1};
  EXPECT_THROW(build_network_2d({x, y, r, {}}, {}), InputError);
  r[1] = 0.1;
  PairList pairs;
  pairs.add(0, 3, PairState::Contact);
  EXPECT_THROW(build_network_2d({x, y, r, {}}, pairs), InputError);
  std::vector<Real> xc{0, 1, 2}, yc{0, 0, 0};
  EXPECT_THROW(build_network_2d({xc, yc, r, {}}, {}), InputError);  // collinear
}
