// The LBM flow benchmarks ([S003] Sec. 3; issue 3): each is a driver run with `fracflow run`.
//   flow/poiseuille  channel between plates driven by a body force, a pressure difference or
//                    an inflow profile; profile against the analytic parabola ([S003] Eq. 14-15)
//   flow/cavity      lid-driven cavity; centre-line profiles against Ghia, Ghia & Shin (1982)
//   flow/cylinder    cylinder between plates: drag, lift, Strouhal number, wall factor lambda
#pragma once
#include "drivers/driver.hpp"

namespace ff::drivers {
Driver flow_poiseuille_driver();
Driver flow_cavity_driver();
Driver flow_cylinder_driver();
}  // namespace ff::drivers
