// Pore network of a 2D bonded-particle packing: the DEM/CFD "fluid flow network" of seed 004
// (Krzaczek, Tejchman & Nitka 2024, Granular Matter 26:38, Appendix B; METHODS.md §5.1–5.3).
//
// Pores ("virtual pores", VPs) are the triangles of the Delaunay triangulation of the disc
// centres (CGAL Delaunay_triangulation_2, exact predicates). Each edge shared by two triangles
// is one channel between those two pores:
//  - S2S ("sphere to sphere") when the edge's two particles are a contact or a bond of the pair
//    list: aperture from Eq. B1 (stress dependent); a broken bond adds its normal opening;
//  - T2T ("triangle to triangle") otherwise: aperture from Eq. B2 (geometric).
// Edges on the convex hull belong to one pore and are no-flow walls.
// Conductance: cubic law of a slit of aperture h and depth t (the out-of-plane thickness),
// g = h^3 t / (12 mu L) (METHODS §5.3b), L the distance between the two pore centroids.
//
// Ids: the caller gives each particle a global id; pores are numbered by the sorted global-id
// triple of their corners and channels by the sorted global-id pair of the crossed edge, so
// the network's numbering does not depend on CGAL's internal order nor on the particles' storage
// order. Storage is SoA; pore -> channel and particle -> pore incidences are CSR arrays so that
// every per-pore or per-particle sum runs in a fixed order (bit-identical on any thread count).
// Units: SI. Positions [m], stresses [Pa] (compression positive), apertures [m].
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "core/types.hpp"

namespace ff::porenet {

// |(x, y)|. std::hypot's guards against overflow are needless at grain scales, and its libm call
// was a third of the 2D network's per-step geometry and forces.
inline Real length_2d(Real x, Real y) { return std::sqrt(x * x + y * y); }

// Particles as SoA spans (z ignored: the specimen plane is x-y). gid may be empty (ids = index).
struct Particles2D {
  std::span<const Real> x, y, radius;
  std::span<const std::int64_t> gid;
};

// State of a contact or bond between two particles, as the DEM reports it.
enum class PairState : std::uint8_t { Contact = 0, Bond = 1, BrokenBond = 2 };

// Contacts and bonds (SoA): particle indices i, j (into Particles2D), state, effective normal
// stress sigma_n [Pa] (compression positive, Eq. B1) and normal opening [m] (broken bonds:
// separation since breakage, > 0 open).
struct PairList {
  std::vector<Index> i, j;
  std::vector<PairState> state;
  std::vector<Real> sigma_n, opening;
  std::size_t size() const { return i.size(); }
  void add(Index a, Index b, PairState s, Real sig = 0, Real open = 0) {
    i.push_back(a);
    j.push_back(b);
    state.push_back(s);
    sigma_n.push_back(sig);
    opening.push_back(open);
  }
};

enum class ChannelKind : std::uint8_t { T2T = 0, S2S = 1 };

// Length e in Eq. B2: the seed's edge between the two triangles (centre to centre), or the free
// gap between the two discs (e - R_a - R_b, >= 0), which closes as the grains touch.
enum class B2Edge : std::uint8_t { Centre = 0, Gap = 1 };

struct NetworkParams {
  Real thickness = 1.0;  // out-of-plane depth t [m]; seed 004: unit depth (Eq. B9)
  // Eq. B1 (Hökmark et al. 2010, modified in seed 004): h = beta (h_inf + (h0 - h_inf) exp(-c sigma_n)).
  Real b1_beta = 1.0;
  Real b1_h0 = 1e-5;           // aperture at zero normal stress [m] (ours; calibrate)
  Real b1_h_inf = 1e-6;        // aperture at infinite normal stress [m] (ours; calibrate)
  Real b1_stress_coeff = 1.5e-7;  // c [1/Pa], seed 004 Eq. B1
  // Eq. B2: h = gamma e cos(90° - omega).
  Real b2_gamma = 1.0;
  B2Edge b2_edge = B2Edge::Gap;
  Real min_aperture = 0;         // floor for every channel [m]
  Real min_void_fraction = 0.01;  // floor on a pore's void / triangle area (overlapping discs)
  // Floor on a pore's void relative to the mean cell volume: hull slivers (near-zero area or
  // volume) would otherwise set the explicit step and drown in the implicit solver's residual.
  Real min_void_relative = 1e-3;
  Real max_cond_ratio = 100;  // 3D: throat conductance <= this x the median (cf. YADE maxKdivKmean)
};

// The network. In 2D pore k has corners pore_v[3k..3k+2] (particle indices, counter-clockwise) and
// channel c joins pores ch_pore[2c] < ch_pore[2c+1] across the edge of particles ch_part[2c],
// ch_part[2c+1]. In 3D (build_network_3d) pores are tetrahedra with corners pore_v[4k..4k+3], channels
// are the throats through shared facets (corners ch_part[3c..3c+2]); ch_edge, ch_sin_omega and pw_*
// are empty.
struct Network2D {
  int dim = 2;
  NetworkParams params;
  Index n_particles = 0;
  // pores
  std::vector<Index> pore_v;
  std::vector<Real> pore_area;    // triangle area [m^2]
  std::vector<Real> pore_cell;    // cell volume = area * t [m^3]
  std::vector<Real> pore_void;    // void volume V_i [m^3] (area minus disc sectors, times t)
  std::vector<Real> pore_cx, pore_cy, pore_cz;  // centroid [m] (pore_cz: 3D only)
  std::vector<Real> pore_px, pore_py, pore_pz;  // 3D only: power centre [m] (the throats' length)
  std::vector<std::uint8_t> pore_hull;  // 1 if one of its edges is on the convex hull
  // channels
  std::vector<Index> ch_pore, ch_part;
  std::vector<ChannelKind> ch_kind;
  std::vector<Index> ch_pair;        // index into the PairList, -1 for T2T
  std::vector<Real> ch_length;       // L: centroid-to-centroid distance (3D: power centres) [m]
  std::vector<Real> ch_edge;         // centre-to-centre edge length [m]
  std::vector<Real> ch_sin_omega;    // sin of the angle between edge and centre line
  std::vector<Real> ch_aperture;     // h [m]
  std::vector<Real> ch_cond;         // h^3 t / (12 L) [m^3]; conductance = ch_cond / mu
  std::vector<Real> ch_shear;        // 3D: 3 per throat, A_f theta_k R_k / sum theta R [m^2]: the channel shear
                                     // on its k-th sphere per unit pressure drop (forces.cpp)
  // CSR: channels of pore k are pc_ch[pc_start[k] .. pc_start[k+1]), sorted by channel id.
  std::vector<Index> pc_start, pc_ch;
  // CSR: pore corners of particle n: (pp_pore, pp_corner) in [pp_start[n], pp_start[n+1]).
  std::vector<Index> pp_start, pp_pore;
  std::vector<std::uint8_t> pp_corner;
  // CSR: channels whose crossed edge has particle n as an end: pw_ch in [pw_start[n], pw_start[n+1]).
  std::vector<Index> pw_start, pw_ch;
  Index n_pairs = 0;          // size of the PairList the network was built with
  Index unmatched_pairs = 0;  // pairs of the list that are not Delaunay edges (no channel)

  // 3D, per step (update_network_3d): the patch force per unit pressure [m^2] of the sphere at corner c
  // of pore k, -int_patch n dA (forces.cpp), at pore_patch[12k + 3c .. 12k + 3c + 2].
  std::vector<Real> pore_patch;

  // 3D with walls (build_network_3d with BoxWalls): wall w (= 2 axis + side) is vertex n_particles + w
  // of pore_v and ch_part; its plane is axis = wall_plane[w], and d_w (side 0: -e_axis, side 1: +e_axis)
  // points from the sample into it. The patch of a wall corner (pore_patch) is A d_w, A the pore's area
  // on the wall: the force on the wall per unit pressure (wall_pressure_forces_3d).
  int n_walls = 0;                       // 0 or 6
  std::array<Real, 6> wall_plane{};      // [m]
  std::vector<std::uint8_t> pore_walls;  // 3D: bit w set if wall w is a corner of pore k
  std::vector<Index> wall_pores, wall_throats;  // pores and throats with a wall corner, ascending
  // CSR: pore corners on wall w: (wp_pore, wp_corner) in [wp_start[w], wp_start[w+1]).
  std::vector<Index> wp_start, wp_pore;
  std::vector<std::uint8_t> wp_corner;
  bool is_wall_vertex(Index v) const { return v >= n_particles; }

  Index hidden_particles = 0;  // 3D regular triangulation: spheres with an empty power cell (no pore)
  // Floor of every pore's void [m^3] (min_void_relative x the mean cell; 2D: of the last update; a pore
  // at the floor keeps its volume as its grains move). 3D: kept from the build for update_network_3d.
  Real void_floor = 0;
  // 3D: kept from the build for update_network_3d
  Real ch_cond_cap = 0, pfv_factor = 1;

  Index n_pores() const { return static_cast<Index>(pore_area.size()); }
  Index n_channels() const { return static_cast<Index>(ch_length.size()); }
};

// Which floor holds pore k's void (pore_geometry): none, the overlap floor (V = min_void_fraction x the
// cell: overlapping grains) or the relative floor (void_floor, a constant). (1 + 1e-12): the floor's
// product rounds differently from the fraction x the cell.
enum class VoidFloor : std::uint8_t { None, Fraction, Relative };
inline VoidFloor void_floor_of(const Network2D& net, Index k) {
  if (!(net.pore_void[k] > net.void_floor)) return VoidFloor::Relative;
  if (net.pore_void[k] <= net.params.min_void_fraction * net.pore_cell[k] * (1 + 1e-12)) return VoidFloor::Fraction;
  return VoidFloor::None;
}

// Triangulates and builds pores, channels and apertures. Throws InputError for mismatched
// spans, non-positive radii, coincident centres, repeated pairs or fewer than 3 non-collinear points.
Network2D build_network_2d(const Particles2D& particles, const PairList& pairs,
                           const NetworkParams& params = {});

// Recomputes pore volumes, centroids, channel lengths and apertures for moved particles and new
// pair states, keeping the topology (between retriangulations). pairs must be the list the
// network was built with (same order), with updated sigma_n / opening / state.
void update_network_2d(Network2D& net, const Particles2D& particles, const PairList& pairs);

// Particles as SoA spans in 3D.
struct Particles3D {
  std::span<const Real> x, y, z, radius;
  std::span<const std::int64_t> gid;
};

// Walls of an axis-aligned box around a 3D sample, planes x = lo[0], x = hi[0], y = lo[1], ...: in the
// triangulation they are PFV's boundary spheres (Chareyre et al. 2012: spheres so large that their
// surface is the wall plane), so the pores between the outermost spheres and the walls are part of the
// network. Without them the network ends at the convex hull of the sphere centres, whose flat hull
// tetrahedra carry throats at the conductance cap along the sample's faces (docs/porenet.md section 9).
struct BoxWalls {
  std::array<Real, 3> lo{}, hi{};
};

// 3D network, PFV style (Chareyre et al. 2012, Transp. Porous Media 94:595; METHODS.md §5.1–5.3a):
// regular (weighted, w = R^2) Delaunay triangulation of the sphere centres (CGAL
// Regular_triangulation_3); pores = tetrahedra with void V = V_tet - sum_k Omega_k R_k^3 / 3 (solid
// angles); throats = shared facets with fluid area A_f = A - sum_k theta_k R_k^2 / 2, hydraulic radius
// R_h = A_f / (sum_k theta_k R_k) (the facet's wetted perimeter: a 2D simplification of PFV's
// volume/surface ratio) and conductance g = pfv_factor A_f R_h^2 / (2 mu L) (ch_cond = g mu),
// L the distance between the pores' power centres. Contacts/bonds do not form extra channels in 3D (not
// yet). With walls (all six; every centre strictly inside the box) a pore may have one to three walls
// as corners: one wall, the prism between the triangle of its three spheres and the wall; two, the
// region between the edge of its two spheres and the box edge; three, the box corner at its sphere.
// Such a pore's power centre lies on its walls (PFV's), and pore_hull marks the pores with a wall.
Network2D build_network_3d(const Particles3D& particles, const NetworkParams& params = {}, Real pfv_factor = 1.0,
                           const BoxWalls* walls = nullptr);

// Pore volumes, centroids and throat conductances for moved spheres, keeping the topology (3D). A
// network with walls takes their new planes from `walls` (nullptr: the planes stay).
void update_network_3d(Network2D& net, const Particles3D& particles, const BoxWalls* walls = nullptr);

// dV/dx [m^2] of the void (without the relative floor) of pore k, which has walls, for a move of the
// sphere at its corner `corner` (0 for a wall corner): central differences of the wall pore's geometry.
void wall_pore_void_gradient(const Network2D& net, const Particles3D& particles, Index k, int corner, Real g[3]);

// Eq. B1 aperture for a contact/bond channel (+ opening for a broken bond).
Real aperture_b1(const NetworkParams& p, PairState state, Real sigma_n, Real opening);

using Network = Network2D;

}  // namespace ff::porenet
