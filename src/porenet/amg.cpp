#include "porenet/amg.hpp"

#include <algorithm>
#include <cmath>

#include "porenet/reduce.hpp"

namespace ff::porenet {

namespace {
void find_diagonals(Index n, const Index* ptr, const Index* col, std::vector<Index>& diag) {
  diag.assign(static_cast<std::size_t>(n), -1);
  for (Index i = 0; i < n; ++i)
    for (Index k = ptr[i]; k < ptr[i + 1]; ++k)
      if (col[k] == i) diag[i] = k;
}
}  // namespace

// Aggregation of level f (Vanek et al. 1996, passes 1-3), the coarse pattern and the entry map.
void Amg::build_level_transfer(Level& f, Level& c, Real eps) {
  const Index n = f.n;
  const Index* ptr = f.ptr;
  const Index* col = f.col;
  const Real* val = f.val;
  auto strong = [&](Index i, Index k) {
    const Index j = col[k];
    if (j == i) return false;
    const Real dij = val[f.diag[i]] * val[f.diag[j]];
    return dij > 0 && val[k] * val[k] > eps * eps * dij;
  };
  constexpr Index kUndecided = -2, kExcluded = -1;
  auto& agg = f.agg;
  agg.assign(static_cast<std::size_t>(n), kUndecided);
  for (Index i = 0; i < n; ++i) {  // no strong coupling (Dirichlet rows, closed pores): smoother only
    bool any = false;
    for (Index k = ptr[i]; k < ptr[i + 1] && !any; ++k) any = strong(i, k);
    if (!any) agg[i] = kExcluded;
  }
  Index na = 0;
  for (Index i = 0; i < n; ++i) {  // pass 1: a node and its strong neighbours, all free
    if (agg[i] != kUndecided) continue;
    bool free = true;
    for (Index k = ptr[i]; k < ptr[i + 1] && free; ++k)
      if (strong(i, k) && agg[col[k]] != kUndecided) free = false;
    if (!free) continue;
    agg[i] = na;
    for (Index k = ptr[i]; k < ptr[i + 1]; ++k)
      if (strong(i, k)) agg[col[k]] = na;
    ++na;
  }
  const std::vector<Index> agg1 = agg;
  for (Index i = 0; i < n; ++i) {  // pass 2: join the most strongly coupled aggregate of pass 1
    if (agg[i] != kUndecided) continue;
    Real best = 0;
    for (Index k = ptr[i]; k < ptr[i + 1]; ++k)
      if (strong(i, k) && agg1[col[k]] >= 0 && std::abs(val[k]) > best) {
        best = std::abs(val[k]);
        agg[i] = agg1[col[k]];
      }
  }
  for (Index i = 0; i < n; ++i) {  // pass 3: the rest with their free strong neighbours
    if (agg[i] != kUndecided) continue;
    agg[i] = na;
    for (Index k = ptr[i]; k < ptr[i + 1]; ++k)
      if (strong(i, k) && agg[col[k]] == kUndecided) agg[col[k]] = na;
    ++na;
  }
  // Rows of each aggregate, ascending (counting sort).
  f.agg_ptr.assign(static_cast<std::size_t>(na) + 1, 0);
  for (Index i = 0; i < n; ++i)
    if (agg[i] >= 0) ++f.agg_ptr[agg[i] + 1];
  for (Index a = 0; a < na; ++a) f.agg_ptr[a + 1] += f.agg_ptr[a];
  f.agg_rows.assign(static_cast<std::size_t>(f.agg_ptr[na]), 0);
  {
    std::vector<Index> fill(f.agg_ptr.begin(), f.agg_ptr.end() - 1);
    for (Index i = 0; i < n; ++i)
      if (agg[i] >= 0) f.agg_rows[fill[agg[i]]++] = i;
  }
  // Coarse pattern: (agg[i], agg[j]) for every stored (i, j) with both aggregated.
  c.n = na;
  c.own_ptr.assign(static_cast<std::size_t>(na) + 1, 0);
  c.own_col.clear();
  std::vector<Index> row;
  for (Index a = 0; a < na; ++a) {
    row.clear();
    for (Index e = f.agg_ptr[a]; e < f.agg_ptr[a + 1]; ++e) {
      const Index i = f.agg_rows[e];
      for (Index k = ptr[i]; k < ptr[i + 1]; ++k)
        if (agg[col[k]] >= 0) row.push_back(agg[col[k]]);
    }
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
    c.own_col.insert(c.own_col.end(), row.begin(), row.end());
    c.own_ptr[a + 1] = static_cast<Index>(c.own_col.size());
  }
  f.entry_map.assign(static_cast<std::size_t>(ptr[n]), -1);
  for (Index i = 0; i < n; ++i) {
    if (agg[i] < 0) continue;
    const Index a = agg[i];
    const Index* b = c.own_col.data() + c.own_ptr[a];
    const Index* e = c.own_col.data() + c.own_ptr[a + 1];
    for (Index k = ptr[i]; k < ptr[i + 1]; ++k)
      if (agg[col[k]] >= 0) f.entry_map[k] = static_cast<Index>(std::lower_bound(b, e, agg[col[k]]) - c.own_col.data());
  }
  c.own_val.assign(c.own_col.size(), 0);
  c.ptr = c.own_ptr.data();
  c.col = c.own_col.data();
  c.val = c.own_val.data();
  find_diagonals(na, c.ptr, c.col, c.diag);
}

void Amg::setup(const CsrView& A) {
  setup_val_.assign(A.val, A.val + A.ptr[A.n]);
  build(A);
}

void Amg::restore(const CsrView& A, std::span<const Real> values) {
  std::vector<Real> v(values.begin(), values.end());  // (values may be setup_values() itself)
  setup_val_.swap(v);
  build({A.n, A.ptr, A.col, setup_val_.data()});
}

void Amg::build(const CsrView& A) {
  levels_.clear();
  levels_.reserve(static_cast<std::size_t>(prm_.max_levels));
  Level& L0 = levels_.emplace_back();
  L0.n = A.n;
  L0.ptr = A.ptr;
  L0.col = A.col;
  L0.val = A.val;
  find_diagonals(A.n, A.ptr, A.col, L0.diag);
  Real eps = prm_.strength;
  while (levels_.back().n > prm_.coarse_size && static_cast<int>(levels_.size()) < prm_.max_levels) {
    Level c;
    build_level_transfer(levels_.back(), c, eps);
    // Too little coarsening (a disconnected or diagonal matrix): stop here.
    if (c.n == 0 || c.n > levels_.back().n * 9 / 10) {
      levels_.back().agg.clear();
      break;
    }
    levels_.push_back(std::move(c));
    Level& cl = levels_.back();
    cl.ptr = cl.own_ptr.data();
    cl.col = cl.own_col.data();
    cl.val = cl.own_val.data();
    // Values now: the next aggregation's strength needs them.
    Level& fl = levels_[levels_.size() - 2];
    const Real s = 1 / prm_.over_interp;
    for (Index a = 0; a < cl.n; ++a)
      for (Index e = fl.agg_ptr[a]; e < fl.agg_ptr[a + 1]; ++e) {
        const Index i = fl.agg_rows[e];
        for (Index k = fl.ptr[i]; k < fl.ptr[i + 1]; ++k)
          if (fl.entry_map[k] >= 0) cl.own_val[fl.entry_map[k]] += s * fl.val[k];
      }
    eps *= 0.5;
  }
  for (auto& L : levels_) {
    const auto n = static_cast<std::size_t>(L.n);
    L.inv_diag.assign(n, 0);
    L.x.assign(2 * n, 0);
    L.b.assign(n, 0);
    L.r.assign(n, 0);
    // The smoother's rows (blocks of kAmgBlock rows; couplings across blocks read the second half of x).
    L.off_ptr.assign(n + 1, 0);
    L.off_slot.clear();
    L.off_src.clear();
    for (Index i = 0; i < L.n; ++i) {
      const Index lo = i / kAmgBlock * kAmgBlock, hi = std::min(L.n, lo + kAmgBlock);
      for (Index k = L.ptr[i]; k < L.ptr[i + 1]; ++k) {
        const Index j = L.col[k];
        if (j == i) continue;
        L.off_slot.push_back(j >= lo && j < hi ? j : L.n + j);
        L.off_src.push_back(k);
      }
      L.off_ptr[static_cast<std::size_t>(i) + 1] = static_cast<Index>(L.off_slot.size());
    }
    L.off_val.assign(L.off_src.size(), 0);
  }
  const Index nc = levels_.back().n;
  chol_.assign(nc <= 2048 ? static_cast<std::size_t>(nc) * static_cast<std::size_t>(nc) : 0, 0);
  refresh(A);
}

void Amg::refresh(const CsrView& A) {
  levels_[0].val = A.val;
  const Real s = 1 / prm_.over_interp;
  for (std::size_t l = 0; l < levels_.size(); ++l) {
    Level& L = levels_[l];
#pragma omp parallel for schedule(static) if (L.n > kParallelMin)
    for (Index i = 0; i < L.n; ++i) {
      L.inv_diag[i] = 1 / L.val[L.diag[i]];
      for (Index e = L.off_ptr[i]; e < L.off_ptr[i + 1]; ++e) L.off_val[e] = L.val[L.off_src[e]];
    }
    if (l + 1 == levels_.size()) break;
    Level& C = levels_[l + 1];
    // Coarse row a gathers the rows of aggregate a in ascending order: no race, a fixed order.
#pragma omp parallel for schedule(static) if (C.n > kParallelMin / 4)
    for (Index a = 0; a < C.n; ++a) {
      for (Index k = C.ptr[a]; k < C.ptr[a + 1]; ++k) C.own_val[k] = 0;
      for (Index e = L.agg_ptr[a]; e < L.agg_ptr[a + 1]; ++e) {
        const Index i = L.agg_rows[e];
        for (Index k = L.ptr[i]; k < L.ptr[i + 1]; ++k)
          if (L.entry_map[k] >= 0) C.own_val[L.entry_map[k]] += s * L.val[k];
      }
    }
  }
  factor_coarsest();
}

// Dense Cholesky L L^T of the coarsest matrix. A pivot lost to cancellation (a closed sample's
// nearly singular Laplacian) is replaced by the diagonal: the factor stays that of an SPD matrix.
void Amg::factor_coarsest() {
  const Level& L = levels_.back();
  const auto n = static_cast<std::size_t>(L.n);
  if (chol_.size() != n * n) return;  // too large: smoothed instead
  std::fill(chol_.begin(), chol_.end(), 0.0);
  for (Index i = 0; i < L.n; ++i)
    for (Index k = L.ptr[i]; k < L.ptr[i + 1]; ++k)
      if (L.col[k] <= i) chol_[static_cast<std::size_t>(i) * n + static_cast<std::size_t>(L.col[k])] = L.val[k];
  for (std::size_t j = 0; j < n; ++j) {
    Real* rj = &chol_[j * n];
    const Real ajj = rj[j];
    Real d = ajj;
    for (std::size_t k = 0; k < j; ++k) d -= rj[k] * rj[k];
    if (!(d > 1e-14 * std::abs(ajj))) d = std::abs(ajj) > 0 ? std::abs(ajj) : 1;
    const Real ljj = std::sqrt(d);
    rj[j] = ljj;
    for (std::size_t i = j + 1; i < n; ++i) {
      Real* ri = &chol_[i * n];
      Real s = ri[j];
      for (std::size_t k = 0; k < j; ++k) s -= ri[k] * rj[k];
      ri[j] = s / ljj;
    }
  }
}

void Amg::solve_coarsest(Level& L) {
  const auto n = static_cast<std::size_t>(L.n);
  if (chol_.size() != n * n) {  // no factor: symmetric Gauss-Seidel
    smooth(L, true, true);
    smooth(L, false, false);
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {  // L y = b
    Real s = L.b[i];
    const Real* ri = &chol_[i * n];
    for (std::size_t k = 0; k < i; ++k) s -= ri[k] * L.x[k];
    L.x[i] = s / ri[i];
  }
  for (std::size_t i = n; i-- > 0;) {  // L^T x = y
    Real s = L.x[i];
    for (std::size_t k = i + 1; k < n; ++k) s -= chol_[k * n + i] * L.x[k];
    L.x[i] = s / chol_[i * n + i];
  }
}

// One hybrid Gauss-Seidel sweep on L.x for L.b; zero_start: L.x is taken as zero.
void Amg::smooth(Level& L, bool forward, bool zero_start) {
  const Index n = L.n;
  const Index nb = (n + kAmgBlock - 1) / kAmgBlock;
  Real* x = L.x.data();
  if (nb > 1) {  // the rows outside each block as the sweep begins (zero_start: zero)
#pragma omp parallel for schedule(static) if (n > kParallelMin)
    for (Index i = 0; i < n; ++i) x[n + i] = zero_start ? 0.0 : x[i];
  }
  const Index* ptr = L.off_ptr.data();
  const Index* slot = L.off_slot.data();
  const Real* val = L.off_val.data();
  const Real* b = L.b.data();
  const Real* inv = L.inv_diag.data();
#pragma omp parallel for schedule(static) if (nb > 1)
  for (Index blk = 0; blk < nb; ++blk) {
    const Index lo = blk * kAmgBlock, hi = std::min(n, lo + kAmgBlock);
    if (zero_start)
      for (Index i = lo; i < hi; ++i) x[i] = 0;
    auto row = [&](Index i) {
      Real s = b[i];
      for (Index e = ptr[i]; e < ptr[i + 1]; ++e) s -= val[e] * x[slot[e]];
      x[i] = s * inv[i];
    };
    if (forward)
      for (Index i = lo; i < hi; ++i) row(i);
    else
      for (Index i = hi - 1; i >= lo; --i) row(i);
  }
}

void Amg::cycle(std::size_t l) {
  Level& L = levels_[l];
  if (l + 1 == levels_.size()) {
    solve_coarsest(L);
    return;
  }
  for (int s = 0; s < prm_.sweeps; ++s) smooth(L, true, s == 0);
  Level& C = levels_[l + 1];
  const Index* ptr = L.ptr;
  const Index* col = L.col;
  const Real* val = L.val;
#pragma omp parallel for schedule(static) if (L.n > kParallelMin)
  for (Index i = 0; i < L.n; ++i) {
    Real s = L.b[i];
    for (Index k = ptr[i]; k < ptr[i + 1]; ++k) s -= val[k] * L.x[col[k]];
    L.r[i] = s;
  }
#pragma omp parallel for schedule(static) if (C.n > kParallelMin / 4)
  for (Index a = 0; a < C.n; ++a) {  // b_c = P^T r
    Real s = 0;
    for (Index e = L.agg_ptr[a]; e < L.agg_ptr[a + 1]; ++e) s += L.r[L.agg_rows[e]];
    C.b[a] = s;
  }
  cycle(l + 1);
#pragma omp parallel for schedule(static) if (L.n > kParallelMin)
  for (Index i = 0; i < L.n; ++i)
    if (L.agg[i] >= 0) L.x[i] += C.x[L.agg[i]];
  for (int s = 0; s < prm_.sweeps; ++s) smooth(L, false, false);
}

void Amg::apply(const Real* r, Real* z) {
  Level& L0 = levels_[0];
#pragma omp parallel for schedule(static) if (L0.n > kParallelMin)
  for (Index i = 0; i < L0.n; ++i) L0.b[i] = r[i];
  cycle(0);
#pragma omp parallel for schedule(static) if (L0.n > kParallelMin)
  for (Index i = 0; i < L0.n; ++i) z[i] = L0.x[i];
}

double Amg::operator_complexity() const {
  if (levels_.empty()) return 0;
  double s = 0;
  for (const auto& L : levels_) s += L.ptr[L.n];
  return s / levels_[0].ptr[levels_[0].n];
}

}  // namespace ff::porenet
