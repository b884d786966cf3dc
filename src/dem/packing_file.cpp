#include "dem/packing_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <istream>
#include <limits>
#include <numeric>
#include <set>
#include <sstream>
#include <string_view>

#include "core/error.hpp"
#include "dem/sample_builder.hpp"

namespace ff::dem {

namespace {

std::vector<std::string_view> split(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    std::size_t j = i;
    while (j < s.size() && !std::isspace(static_cast<unsigned char>(s[j]))) ++j;
    if (j > i) out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

// The whole token as a finite number (a leading '+' allowed), or false.
bool to_real(std::string_view t, double& v) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  return r.ec == std::errc() && r.ptr == t.data() + t.size() && std::isfinite(v);
}

bool to_integer(std::string_view t, long long& v) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

}  // namespace

PackingFile parse_packing(std::istream& in, const std::string& name) {
  PackingFile p;
  std::set<std::pair<Index, Index>> seen;
  std::string line;
  long number = 0;
  long bonds_line = 0;
  auto fail = [&](const std::string& what) { throw InputError(fmt::format("{}:{}: {}", name, number, what)); };
  while (std::getline(in, line)) {
    ++number;
    std::string_view s(line);
    if (const auto hash = s.find('#'); hash != std::string_view::npos) s = s.substr(0, hash);
    const auto tok = split(s);
    if (tok.empty()) continue;
    if (tok.size() == 1 && tok[0] == "bonds") {
      if (bonds_line) fail(fmt::format("a second 'bonds' line (the first is line {})", bonds_line));
      if (p.pos.empty()) fail("'bonds' before any particle line 'x y z r'");
      bonds_line = number;
      p.has_bond_list = true;
      continue;
    }
    if (!bonds_line) {
      if (tok.size() != 4)
        fail(fmt::format("expected a particle 'x y z r' (4 numbers), got {} field{}: '{}'", tok.size(),
                         tok.size() == 1 ? "" : "s", s));
      double v[4];
      static constexpr const char* kWhat[4] = {"x", "y", "z", "r"};
      for (int k = 0; k < 4; ++k)
        if (!to_real(tok[k], v[k])) fail(fmt::format("{} = '{}' is not a finite number", kWhat[k], tok[k]));
      if (v[3] <= 0) fail(fmt::format("radius r = {} must be positive", tok[3]));
      if (p.pos.size() >= static_cast<std::size_t>(std::numeric_limits<Index>::max()))
        fail("too many particles for a 32-bit index");
      p.pos.emplace_back(v[0], v[1], v[2]);
      p.radius.push_back(v[3]);
      continue;
    }
    if (tok.size() != 2)
      fail(fmt::format("expected a bond 'i j' (two particle indices, after 'bonds' on line {}), got {} field{}: '{}'",
                       bonds_line, tok.size(), tok.size() == 1 ? "" : "s", s));
    long long ij[2];
    const long long n = static_cast<long long>(p.pos.size());
    for (int k = 0; k < 2; ++k) {
      if (!to_integer(tok[k], ij[k])) fail(fmt::format("bond index '{}' is not an integer", tok[k]));
      if (ij[k] < 0 || ij[k] >= n)
        fail(fmt::format("bond index {} is out of range: the file has {} particles, indices 0 to {} (0-based)", ij[k], n,
                         n - 1));
    }
    if (ij[0] == ij[1]) fail(fmt::format("bond of particle {} with itself", ij[0]));
    const std::pair<Index, Index> b{static_cast<Index>(std::min(ij[0], ij[1])), static_cast<Index>(std::max(ij[0], ij[1]))};
    if (!seen.insert(b).second) fail(fmt::format("bond {} {} is listed twice", b.first, b.second));
    p.bonds.emplace_back(b.first, b.second);
  }
  if (in.bad()) throw InputError(fmt::format("{}: read error after line {}", name, number));
  if (p.pos.empty()) throw InputError(fmt::format("{}: no particle lines 'x y z r' in the file", name));
  return p;
}

PackingFile read_packing_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("cannot open packing file '{}': {}", path, std::strerror(errno)));
  return parse_packing(in, path);
}

void write_packing_file(const std::string& path, const PackingFile& p, const std::string& comment) {
  std::ofstream out(path);
  if (!out) throw Error(fmt::format("cannot write packing file '{}': {}", path, std::strerror(errno)));
  std::istringstream lines(comment);
  for (std::string l; std::getline(lines, l);) out << "# " << l << '\n';
  out << "# x y z r [m], one particle per line; then 'bonds' and one 0-based pair 'i j' per line\n";
  for (std::size_t i = 0; i < p.pos.size(); ++i)
    out << fmt::format("{:.17g} {:.17g} {:.17g} {:.17g}\n", p.pos[i].x(), p.pos[i].y(), p.pos[i].z(), p.radius[i]);
  if (p.has_bond_list) {
    out << "bonds\n";
    for (const auto& [i, j] : p.bonds) out << i << ' ' << j << '\n';
  }
  out.flush();
  if (!out) throw Error(fmt::format("error writing packing file '{}'", path));
}

SampleInfo place_packing(const PackingFile& p, const Config& cfg, DemSystem& sys, int group, bool reorder) {
  const auto t0 = std::chrono::steady_clock::now();
  if (p.pos.empty()) throw InputError("packing: no particles");
  if (group < 0 || group >= sys.materials.groups()) throw Error("internal: place_packing() with a bad group");
  if (!p.bonds.empty() && !sys.materials.has_bonds())
    throw InputError("the packing file lists bonds but dem.bond_law = none: set a bond law or remove the 'bonds' section");
  const std::size_t n = p.pos.size();
  std::vector<std::size_t> order(n);  // order[new] = old
  std::iota(order.begin(), order.end(), 0);
  if (reorder) order = spatial_order(p.pos, p.radius);  // as genesis orders its particles
  std::vector<Index> new_index(n);
  for (std::size_t k = 0; k < n; ++k) new_index[order[k]] = static_cast<Index>(k);

  auto& P = sys.particles;
  const int dim = sys.settings.dim;
  P = ParticleStore{};
  P.resize(n);
  Real rsum = 0;
  for (std::size_t k = 0; k < n; ++k) {
    P.pos[k] = p.pos[order[k]];
    P.radius[k] = p.radius[order[k]];
    P.group[k] = group;
    P.set_mass_from_density(k, sys.materials.density[group], dim);
    rsum += P.radius[k];
  }
  sys.walls.clear();
  sys.bonds = BondSet{};
  sys.settings.skin = cfg.real("dem.skin_ratio") * rsum / static_cast<Real>(n);
  SampleInfo info;
  info.dim = dim;
  info.axis = dim == 3 ? 2 : 1;
  info.cylinder = false;
  if (sys.materials.has_bonds()) {
    if (p.has_bond_list) {
      std::vector<std::pair<Index, Index>> bonds;
      bonds.reserve(p.bonds.size());
      for (const auto& [i, j] : p.bonds) bonds.emplace_back(std::min(new_index[i], new_index[j]), std::max(new_index[i], new_index[j]));
      if (reorder) std::sort(bonds.begin(), bonds.end());
      for (const auto& [i, j] : bonds) sys.add_bond(i, j);
      info.bonds = bonds.size();
    } else {
      info.bonds = install_sample_bonds(cfg, sys);
    }
  }
  std::vector<int> degree(n, 0);
  for (std::size_t b = 0; b < sys.bonds.i.size(); ++b) {
    ++degree[sys.bonds.i[b]];
    ++degree[sys.bonds.j[b]];
  }
  for (int d : degree) info.floaters += d < (dim == 3 ? 3 : 2);
  Vec3 lo = P.pos[0], hi = P.pos[0];
  Real solid = 0;
  for (std::size_t i = 0; i < n; ++i) {
    lo = lo.cwiseMin(P.pos[i] - Vec3::Constant(P.radius[i]));
    hi = hi.cwiseMax(P.pos[i] + Vec3::Constant(P.radius[i]));
    const Real r = P.radius[i];
    solid += dim == 3 ? 4.0 / 3.0 * kPi * r * r * r : kPi * r * r;
  }
  const Vec3 size = hi - lo;
  info.height = size[info.axis];
  info.width = size.x();
  info.area = dim == 3 ? size.x() * size.y() : size.x();
  info.volume = info.area * info.height;
  info.porosity = info.volume > 0 ? 1.0 - solid / info.volume : 0;
  sys.time = 0;
  sys.step_count = 0;
  sys.cracks = CrackLog{};
  sys.initialise();
  info.genesis_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return info;
}

}  // namespace ff::dem
