// How a pore's pressure pushes the grains at its corners (DemPorenetCoupling in 2D, DemPorenet3D).
#pragma once
#include <cstdint>

namespace ff::coupling {

// VoidGradient: p dV_i/dx_j, the change of pore i's void (the volume the flow's mass balance uses:
// 2D the triangle less the three disc sectors, porenet::void_gradient_2d; 3D the tetrahedron less the
// four sphere sectors, DemPorenet3D::void_gradient, with the network's floors: a pore held at a floor
// pushes with the floored void's gradient, 0 at the relative floor) as grain j moves. The fluid's work on
// the grains is then sum p dV, and a pore whose pressure follows its void is a conservative spring.
// Surface: the pressure integrated over the grain's wetted surface inside the pore: seed 004's B26-B27
// (the disc's arc inside the triangle, porenet::add_pressure_forces) in 2D, the spherical patches inside
// the tetrahedron (PFV style, porenet::add_pressure_forces_3d) in 3D. It is not the gradient of the void
// (the two differ by the pressure on the throats' open parts of the pore's faces), so the coupled stiffness
// is not symmetric and a closed loop of grain motion does work: a liquid-full specimen can flutter
// (kinetic energy growing before any bond breaks; docs/saturated.md, "Pressure forces"). Both give zero
// net force on an interior grain at uniform pressure (VoidGradient: where no pore around it is floored).
enum class PressureForce : std::uint8_t { VoidGradient = 0, Surface = 1 };

// The scenario's spelling (fluid.pressure_forces) and summary.json's.
inline const char* name(PressureForce f) { return f == PressureForce::Surface ? "surface" : "void_gradient"; }

}  // namespace ff::coupling
