// The classical breakdown pressures and the sweep report (validate-hydrofrac).
#include <gtest/gtest.h>

#include <cmath>

#include "drivers/hydrofrac/breakdown_theory.hpp"
#include "drivers/hydrofrac/kirsch.hpp"

using namespace ff::drivers::hydrofrac;

// Hubbert & Willis (1957): P_b = 3 sh - sH + T - p0; e.g. sh = 10, sH = 20, T = 5 MPa: 15 MPa.
// Haimson & Fairhurst (1967): (3 sh - sH + T - 2 eta p0)/(2 - 2 eta): eta = 0.5 is H&W, eta = 0
// halves it (p0 = 0); with p0 = 5 MPa and eta = 0.25: (30 - 20 + 5 - 2.5)/1.5 = 8.333 MPa.
TEST(BreakdownTheory, ClassicalFormulas) {
  EXPECT_DOUBLE_EQ(hubbert_willis(20e6, 10e6, 5e6), 15e6);
  EXPECT_DOUBLE_EQ(hubbert_willis(20e6, 10e6, 5e6, 2e6), 13e6);
  EXPECT_NEAR(haimson_fairhurst(20e6, 10e6, 5e6, 0.5), hubbert_willis(20e6, 10e6, 5e6), 1e-6);
  EXPECT_NEAR(haimson_fairhurst(20e6, 10e6, 5e6, 0.0), 7.5e6, 1e-6);
  EXPECT_NEAR(haimson_fairhurst(20e6, 10e6, 5e6, 0.25, 5e6), 12.5e6 / 1.5, 1e-6);
}

// Hubbert-Willis is Kirsch's hoop stress at the wall where it is least, t = 0 (along sigma_H):
// s_tt(a, 0) = 3 sh - sH - p, which is -T at P_b.
TEST(BreakdownTheory, HubbertWillisIsKirschAtTheWall) {
  const double sH = 12e6, sh = 5e6, T = 4e6, a = 0.1, pi = 3.14159265358979;
  const double pb = hubbert_willis(sH, sh, T);
  EXPECT_NEAR(kirsch(sH, sh, pb, a, a, 0).tt, -T, 1e-6);
  EXPECT_NEAR(kirsch(sH, sh, pb, a, a, 0).rr, pb, 1e-6);  // the wall carries the pressure
  EXPECT_NEAR(kirsch(sH, sh, pb, a, a, 0.3).rt, 0, 1e-6);  // and no shear
  EXPECT_NEAR(kirsch(sH, sh, 0, a, 1e3 * a, 0).rr, sH, 1e-3 * sH);  // far field
  EXPECT_NEAR(kirsch(sH, sh, 0, a, 1e3 * a, 0.5 * pi).rr, sh, 1e-3 * sH);
  // The pressure's sigma_xx = p a^2 cos(2t)/r^2 = p a^2 Re(1/z^2) is harmonic: its mean over a
  // disc equals the centre value p a^2/d^2 (the quadrature of kirsch_average, within 1%).
  const auto avg = kirsch_average(0, 0, 1.0, a, 3 * a, 0, a, 2);
  EXPECT_NEAR(avg.x(), 1.0 / 9.0, 0.01 / 9.0);
  EXPECT_NEAR(avg.y(), -1.0 / 9.0, 0.01 / 9.0);
}

TEST(BreakdownTheory, LineFitAndReport) {
  const LineFit f = fit_line({1, 2, 3, 4}, {5, 8, 11, 14});
  EXPECT_EQ(f.points, 4);
  EXPECT_NEAR(f.slope, 3, 1e-12);
  EXPECT_NEAR(f.offset, 2, 1e-12);
  EXPECT_NEAR(f.r2, 1, 1e-12);
  EXPECT_EQ(fit_line({1, 1}, {2, 3}).points, 0);
  EXPECT_EQ(fit_line({1, NAN, 3}, {1, 2, 3}).points, 2);
  std::vector<BreakdownPoint> pts(2);
  pts[0] = {4e6, 1e6, 20e6, 15e6, 12e6, 2.0, 1500, 10};
  pts[1] = {4e6, 3e6, 26e6, 21e6, 15e6, -3.0, 1500, 10};
  SweepContext c;
  c.tensile_strength = 8e6;
  const std::string r = breakdown_report(pts, c);
  EXPECT_NE(r.find("| 4.00 | 1.00 | 15.00 | 20.00 | 12.00 | 7.00 | 3.50 |"), std::string::npos) << r;
  EXPECT_NE(r.find("breakdown, sleeve (vs H&W) | 3.00 | 17.00"), std::string::npos) << r;
}
