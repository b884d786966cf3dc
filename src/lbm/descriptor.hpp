// Lattice descriptors as compile-time types (METHODS §4.1): velocities c_q, weights w_q and
// opposite directions. Lattice units throughout: dx = dt = 1, c_s^2 = 1/3.
//
// Direction 0 is the rest population. Directions are listed in opposite pairs
// (q, q+1) for q odd, so that TRT and bounce-back can loop over "half" the lattice.
#pragma once
#include <array>
#include <string_view>

namespace ff::lbm {

inline constexpr double kCs2 = 1.0 / 3.0;

namespace detail {
template <int Q>
constexpr std::array<int, Q> opposites(const std::array<std::array<int, 3>, Q>& c) {
  std::array<int, Q> o{};
  for (int q = 0; q < Q; ++q)
    for (int p = 0; p < Q; ++p)
      if (c[p][0] == -c[q][0] && c[p][1] == -c[q][1] && c[p][2] == -c[q][2]) o[q] = p;
  return o;
}
}  // namespace detail

// D2Q9 (Qian, d'Humieres & Lallemand 1992).
struct D2Q9 {
  static constexpr int D = 2;
  static constexpr int Q = 9;
  static constexpr std::string_view name = "D2Q9";
  static constexpr std::array<std::array<int, 3>, Q> c = {{{0, 0, 0},
                                                          {1, 0, 0}, {-1, 0, 0},
                                                          {0, 1, 0}, {0, -1, 0},
                                                          {1, 1, 0}, {-1, -1, 0},
                                                          {1, -1, 0}, {-1, 1, 0}}};
  static constexpr std::array<double, Q> w = {4.0 / 9,  1.0 / 9,  1.0 / 9,  1.0 / 9, 1.0 / 9,
                                              1.0 / 36, 1.0 / 36, 1.0 / 36, 1.0 / 36};
  static constexpr std::array<int, Q> opp = detail::opposites<Q>(c);
};

// D3Q19 (rest, 6 face neighbours, 12 edge neighbours).
struct D3Q19 {
  static constexpr int D = 3;
  static constexpr int Q = 19;
  static constexpr std::string_view name = "D3Q19";
  static constexpr std::array<std::array<int, 3>, Q> c = {{{0, 0, 0},
                                                          {1, 0, 0}, {-1, 0, 0},
                                                          {0, 1, 0}, {0, -1, 0},
                                                          {0, 0, 1}, {0, 0, -1},
                                                          {1, 1, 0}, {-1, -1, 0},
                                                          {1, -1, 0}, {-1, 1, 0},
                                                          {1, 0, 1}, {-1, 0, -1},
                                                          {1, 0, -1}, {-1, 0, 1},
                                                          {0, 1, 1}, {0, -1, -1},
                                                          {0, 1, -1}, {0, -1, 1}}};
  static constexpr std::array<double, Q> w = {1.0 / 3,  1.0 / 18, 1.0 / 18, 1.0 / 18, 1.0 / 18,
                                              1.0 / 18, 1.0 / 18, 1.0 / 36, 1.0 / 36, 1.0 / 36,
                                              1.0 / 36, 1.0 / 36, 1.0 / 36, 1.0 / 36, 1.0 / 36,
                                              1.0 / 36, 1.0 / 36, 1.0 / 36, 1.0 / 36};
  static constexpr std::array<int, Q> opp = detail::opposites<Q>(c);
};

// Compile-time checks of the tables: weights sum to one, second moment is c_s^2 I,
// and directions come in opposite pairs (q, q+1).
template <class L>
constexpr bool descriptor_is_consistent() {
  double s = 0, sxx = 0, syy = 0, sxy = 0;
  for (int q = 0; q < L::Q; ++q) {
    s += L::w[q];
    sxx += L::w[q] * L::c[q][0] * L::c[q][0];
    syy += L::w[q] * L::c[q][1] * L::c[q][1];
    sxy += L::w[q] * L::c[q][0] * L::c[q][1];
    if (q > 0 && L::opp[q] != ((q % 2 == 1) ? q + 1 : q - 1)) return false;
  }
  auto near = [](double a, double b) { return a - b < 1e-14 && b - a < 1e-14; };
  return L::opp[0] == 0 && near(s, 1.0) && near(sxx, kCs2) && near(syy, kCs2) && near(sxy, 0.0);
}
static_assert(descriptor_is_consistent<D2Q9>());
static_assert(descriptor_is_consistent<D3Q19>());

}  // namespace ff::lbm
