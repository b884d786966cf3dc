// Solver::finalize(): classifies the cells once per geometry. Ghost cells take their
// face's condition; fluid cells whose every neighbour is fluid become bulk spans, the others
// boundary cells with their wall links (and link fractions) and open-face data.
#include <fmt/format.h>

#include <unordered_map>

#include "core/error.hpp"
#include "lbm/solver.hpp"

namespace ff::lbm {

template <class L, class T>
void Solver<L, T>::finalize() {
  const Grid& g = grid_;
  auto is_open = [](FaceCondition::Kind k) {
    return k == FaceCondition::Kind::Velocity || k == FaceCondition::Kind::Pressure || k == FaceCondition::Kind::Outflow;
  };
  for (int f = 0; f < kNumFaces; ++f)
    if (faces_[f].kind == FaceCondition::Kind::Outflow && g.n(f / 2) < 3)
      throw InputError(fmt::format("LBM outflow face {} needs at least 3 cells along {} (it copies from the layer "
                                   "inside it), the lattice has {}",
                                   face_name(f), "xyz"[f / 2], g.n(f / 2)));
  // 1. Ghost cells: walls are solid cells owned by the face object, open faces are Open.
  for (int z = -g.gz; z < g.nz + g.gz; ++z)
    for (int y = -1; y <= g.ny; ++y)
      for (int x = -1; x <= g.nx; ++x) {
        if (g.is_interior(x, y, z)) continue;
        const CellIndex i = g.index(x, y, z);
        const int f = g.ghost_face(x, y, z);
        const bool open = is_open(faces_[f].kind);
        type_[i] = open ? CellType::Open : CellType::Solid;
        object_[i] = open ? -1 : std::int16_t(f);
      }

  psm_kinds_stale_ = true;
  spans_.clear();
  bcells_.clear();
  links_.clear();
  open_.clear();
  outflow_cells_.clear();
  bulk_donors_.clear();
  for (auto& o : objects_) o.links = 0;

  // 2. Outflow donors: the fluid cell x + n one layer inside each fluid node x of an outflow face,
  //    one row of the donor buffer each (a donor shared by the two faces of a 3-cell axis once).
  std::unordered_map<CellIndex, std::int32_t> donor_row;
  for (int f = 0; f < kNumFaces; ++f) {
    if (faces_[f].kind != FaceCondition::Kind::Outflow) continue;
    const int a = f / 2, sign = f % 2 == 0 ? 1 : -1;
    for (int z = 0; z < g.nz; ++z)
      for (int y = 0; y < g.ny; ++y)
        for (int x = 0; x < g.nx; ++x) {
          const int c[3] = {x, y, z};
          if (c[a] != (sign > 0 ? 0 : g.n(a) - 1) || type_[g.index(x, y, z)] != CellType::Fluid) continue;
          const CellIndex d = g.index(x + (a == 0) * sign, y + (a == 1) * sign, z + (a == 2) * sign);
          if (type_[d] == CellType::Fluid) donor_row.emplace(d, std::int32_t(donor_row.size()));
        }
  }

  for (int z = 0; z < g.nz; ++z)
    for (int y = 0; y < g.ny; ++y) {
      int run_start = -1;
      auto close_run = [&](int x_end) {
        if (run_start >= 0) spans_.push_back(Span{run_start, y, z, x_end - run_start});
        run_start = -1;
      };
      for (int x = 0; x < g.nx; ++x) {
        const CellIndex i = g.index(x, y, z);
        if (type_[i] != CellType::Fluid) {
          close_run(x);
          continue;
        }
        // Open face this cell lies on (at most one).
        int open_axis = -1, open_sign = 0;
        for (int a = 0; a < L::D; ++a) {
          const int c = a == 0 ? x : a == 1 ? y : z;
          for (int side = 0; side < 2; ++side) {
            if (!is_open(faces_[2 * a + side].kind)) continue;
            if (c != (side == 0 ? 0 : g.n(a) - 1)) continue;
            if (open_axis >= 0)
              throw InputError(fmt::format("LBM cell ({}, {}, {}) lies on two open faces ({} and {}); make one of the "
                                           "crossing faces a wall or periodic",
                                           x, y, z, face_name(2 * open_axis + (open_sign > 0 ? 0 : 1)),
                                           face_name(2 * a + side)));
            open_axis = a;
            open_sign = side == 0 ? 1 : -1;
          }
        }
        BoundaryCell b;
        b.cell = i;
        b.x = x;
        b.y = y;
        b.z = z;
        if (open_axis >= 0)
          for (int q = 1; q < Q; ++q)
            if (L::c[q][open_axis] * open_sign > 0) b.open_mask |= 1u << q;
        for (int q = 1; q < Q; ++q) {
          if (b.open_mask & (1u << q)) continue;
          const CellIndex s = g.neighbour(x, y, z, -L::c[q][0], -L::c[q][1], -L::c[q][2]);
          if (type_[s] == CellType::Solid) b.link_mask |= 1u << q;
          else if (type_[s] == CellType::Open)
            throw InputError(fmt::format("LBM cell ({}, {}, {}) receives fluid from an open face it does not lie on; "
                                         "open faces may only meet walls or periodic faces",
                                         x, y, z));
        }
        const bool bulk = b.link_mask == 0 && b.open_mask == 0;
        // A bulk donor stays in the bulk; its populations are copied before each step.
        const auto donor = donor_row.find(i);
        if (bulk && donor != donor_row.end()) bulk_donors_.push_back(BulkDonor{i, x, y, z, donor->second});
        // Periodic x needs no split: the bulk kernel streams the first and last cells of a
        // row through the ghost columns (bulk_sweep.cpp), so whole rows stay one span.
        if (!bulk) close_run(x);
        if (bulk) {
          if (run_start < 0) run_start = x;
          continue;
        }
        if (donor != donor_row.end()) b.capture = donor->second;
        // Boundary cell: links to solids, then its open-face data.
        b.first_link = std::int32_t(links_.size());
        for (int q = 1; q < Q; ++q) {
          if (!(b.link_mask & (1u << q))) continue;
          const int o = L::opp[q];
          const CellIndex s = g.neighbour(x, y, z, -L::c[q][0], -L::c[q][1], -L::c[q][2]);
          Link k;
          k.cell = std::int32_t(bcells_.size());
          k.q = std::uint8_t(q);
          k.object = object_[s];
          SolidObject& obj = objects_[k.object];
          k.scheme = obj.scheme;
          const CellIndex second = g.neighbour(x, y, z, L::c[q][0], L::c[q][1], L::c[q][2]);
          k.has_second = type_[second] == CellType::Fluid && !(b.open_mask & (1u << o));
          if (obj.shape && k.scheme != WallScheme::HalfwayBounceBack) {
            const Vec3 xf(x, y, z);
            const Vec3 xb = xf + Vec3(L::c[o][0], L::c[o][1], L::c[o][2]);
            k.delta = float(entry_fraction(*obj.shape, xf, xb));
          }
          ++obj.links;
          links_.push_back(k);
        }
        b.num_links = std::int32_t(links_.size()) - b.first_link;
        if (open_axis >= 0) {
          const FaceCondition& fc = faces_[2 * open_axis + (open_sign > 0 ? 0 : 1)];
          OpenNode<T> nd;
          nd.axis = std::int8_t(open_axis);
          nd.sign = std::int8_t(open_sign);
          nd.pressure = fc.kind == FaceCondition::Kind::Pressure;
          nd.face = std::int8_t(2 * open_axis + (open_sign > 0 ? 0 : 1));
          if (fc.kind == FaceCondition::Kind::Outflow) {
            nd.kind = fc.outflow == FaceCondition::Outflow::Convective ? OpenKind::Convective : OpenKind::ZeroGradient;
            const int n[3] = {open_axis == 0 ? open_sign : 0, open_axis == 1 ? open_sign : 0,
                              open_axis == 2 ? open_sign : 0};
            const auto d = donor_row.find(g.index(x + n[0], y + n[1], z + n[2]));
            nd.donor = d == donor_row.end() ? -1 : d->second;  // -1: solid donor
            nd.density_free = fc.outflow_density_free;
            nd.ghost = g.index(x - n[0], y - n[1], z - n[2]);
            b.outflow = true;
            outflow_cells_.push_back(std::int32_t(bcells_.size()));
          } else {
            nd.kind = nd.pressure ? OpenKind::Pressure : OpenKind::Velocity;
            nd.rho = T(fc.density);
            const Vec3 u = fc.profile ? fc.profile(x, y, z) : fc.velocity;
            for (int a = 0; a < 3; ++a) nd.u[a] = T(a < L::D ? u[a] : 0.0);
            if (nd.pressure) nd.u[open_axis] = 0;  // the normal velocity follows from the density
          }
          b.open = std::int32_t(open_.size());
          open_.push_back(nd);
        }
        bcells_.push_back(b);
      }
      close_run(g.nx);
    }
  num_bulk_cells_ = 0;
  for (auto& sp : spans_) num_bulk_cells_ += sp.n;
  // Spans come in lattice order: each row's are consecutive (the sweep with particle links, by row).
  const std::int64_t nrows = std::int64_t(g.ny) * g.nz;
  row_span_.assign(std::size_t(nrows) + 1, 0);
  for (auto& sp : spans_) ++row_span_[std::size_t(sp.y + std::int64_t(g.ny) * sp.z) + 1];
  for (std::int64_t r = 0; r < nrows; ++r) row_span_[std::size_t(r) + 1] += row_span_[std::size_t(r)];
  link_saved_.assign(links_.size(), T(0));
  donor_g_.assign(std::size_t(Q) * donor_row.size(), T(0));
  convective_u_.fill(T(0));
  link_force_.assign(3 * links_.size(), 0.0);
  compute_link_velocities();
}

template void Solver<D2Q9, double>::finalize();
template void Solver<D2Q9, float>::finalize();
template void Solver<D3Q19, double>::finalize();
template void Solver<D3Q19, float>::finalize();

}  // namespace ff::lbm
