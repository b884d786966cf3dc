#include "dem/bond_set.hpp"

#include <algorithm>

namespace ff::dem {

std::size_t BondSet::intact() const { return static_cast<std::size_t>(std::count(broken.begin(), broken.end(), 0)); }

void BondSet::add(Index a, Index b, int pt) {
  i.push_back(a);
  j.push_back(b);
  pair.push_back(pt);
  broken.push_back(0);
}

void BondSet::build_adjacency(std::size_t n) {
  const std::size_t nb = i.size();
  adj_offset_.assign(n + 1, 0);
  for (std::size_t b = 0; b < nb; ++b) {
    ++adj_offset_[i[b] + 1];
    ++adj_offset_[j[b] + 1];
  }
  for (std::size_t p = 0; p < n; ++p) adj_offset_[p + 1] += adj_offset_[p];
  adj_.resize(adj_offset_[n]);
  fill_.assign(adj_offset_.begin(), adj_offset_.end() - 1);
  for (std::size_t b = 0; b < nb; ++b) {
    adj_[fill_[i[b]]++] = static_cast<std::int64_t>(b) << 1;
    adj_[fill_[j[b]]++] = (static_cast<std::int64_t>(b) << 1) | 1;
  }
  load_.assign(nb, PairLoad{});
  fail_flag_.assign(nb, 0);
}

void BondSet::compact(std::size_t n_particles) {
  std::size_t k = 0;
  for (std::size_t b = 0; b < i.size(); ++b) {
    if (broken[b]) continue;
    i[k] = i[b];
    j[k] = j[b];
    pair[k] = pair[b];
    broken[k] = 0;
    std::apply([&](auto&... st) { ((st.empty() ? void() : void(st[k] = st[b])), ...); }, states);
    ++k;
  }
  if (k == i.size()) return;
  i.resize(k);
  j.resize(k);
  pair.resize(k);
  broken.resize(k);
  std::apply([&](auto&... st) { ((st.empty() ? void() : st.resize(k)), ...); }, states);
  build_adjacency(n_particles);
}

}  // namespace ff::dem
