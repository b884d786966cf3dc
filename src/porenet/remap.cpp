#include "porenet/remap.hpp"

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <fmt/format.h>

#include "core/error.hpp"

namespace ff::porenet {
namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb2 = CGAL::Triangulation_vertex_base_with_info_2<Index, Kernel>;
using Dt2 = CGAL::Delaunay_triangulation_2<Kernel, CGAL::Triangulation_data_structure_2<Vb2>>;
using Vb3 = CGAL::Triangulation_vertex_base_with_info_3<Index, Kernel>;
using Dt3 = CGAL::Delaunay_triangulation_3<Kernel, CGAL::Triangulation_data_structure_3<Vb3>>;
}  // namespace

std::vector<Index> nearest_pores(const Network2D& from, const Network2D& to) {
  if (from.dim != to.dim) throw InputError("porenet: remapping between a 2D and a 3D network");
  if (from.n_pores() == 0) throw InputError("porenet: remapping from an empty network");
  std::vector<Index> out(static_cast<std::size_t>(to.n_pores()));
  if (from.dim == 2) {
    std::vector<std::pair<Kernel::Point_2, Index>> pts;
    for (Index k = 0; k < from.n_pores(); ++k) pts.push_back({Kernel::Point_2(from.pore_cx[k], from.pore_cy[k]), k});
    Dt2 dt;
    dt.insert(pts.begin(), pts.end());
    Dt2::Face_handle hint;
    for (Index k = 0; k < to.n_pores(); ++k) {
      const auto v = dt.nearest_vertex(Kernel::Point_2(to.pore_cx[k], to.pore_cy[k]), hint);
      hint = v->face();
      out[k] = v->info();
    }
  } else {
    std::vector<std::pair<Kernel::Point_3, Index>> pts;
    for (Index k = 0; k < from.n_pores(); ++k)
      pts.push_back({Kernel::Point_3(from.pore_cx[k], from.pore_cy[k], from.pore_cz[k]), k});
    Dt3 dt;
    dt.insert(pts.begin(), pts.end());
    Dt3::Cell_handle hint;
    for (Index k = 0; k < to.n_pores(); ++k) {
      const auto v = dt.nearest_vertex(Kernel::Point_3(to.pore_cx[k], to.pore_cy[k], to.pore_cz[k]), hint);
      hint = v->cell();
      out[k] = v->info();
    }
  }
  return out;
}

void remap_single_phase(const Network2D& old_net, SinglePhaseFlow& old_flow, const Network2D& new_net,
                        SinglePhaseFlow& new_flow) {
  const auto near = nearest_pores(old_net, new_net);
  std::vector<Real> m(near.size());
  Real total = 0;
  for (std::size_t k = 0; k < near.size(); ++k) {
    m[k] = old_flow.density()[near[k]] * new_net.pore_void[k];
    total += m[k];
  }
  const Real scale = old_flow.total_mass() / total;
  for (Real& v : m) v *= scale;
  new_flow.load_masses(m);
}

RemapChange remap_two_phase(const Network2D& old_net, TwoPhaseFlow& old_flow, const Network2D& new_net,
                            TwoPhaseFlow& new_flow, RemapConserve conserve) {
  const auto near = nearest_pores(old_net, new_net);
  const std::size_t n = near.size();
  std::vector<Real> mq(n), mp(n);
  Real tq = 0, tp = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const Index o = near[k];
    const Real a = old_flow.liquid_fraction()[o], V = new_net.pore_void[k];
    mq[k] = a * V * old_flow.liquid_density()[o];
    mp[k] = (1 - a) * V * old_flow.gas_density()[o];
    tq += mq[k];
    tp += mp[k];
  }
  const Real old_q = old_flow.total_liquid_mass(), old_p = old_flow.total_gas_mass();
  if (conserve == RemapConserve::Mass) {
    const Real sq = tq > 0 ? old_q / tq : 0, sp = tp > 0 ? old_p / tp : 0;
    for (std::size_t k = 0; k < n; ++k) {
      mq[k] *= sq;
      mp[k] *= sp;
    }
  }
  new_flow.load_masses(mq, mp);
  return {new_flow.total_liquid_mass() - old_q, new_flow.total_gas_mass() - old_p};
}

}  // namespace ff::porenet
