// Error types. Every message says what was wrong and what to change.
#pragma once
#include <stdexcept>
#include <string>

namespace ff {
// Base for all fracflow errors.
struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// Bad user input: scenario file, command line, geometry file.
struct InputError : Error {
  using Error::Error;
};
// The numerics became unstable (NaN, time step too large, LBM Mach number...). The run
// writes a last checkpoint before reporting it.
struct NumericalError : Error {
  using Error::Error;
};
// The DEM's positions or spins became NaN/inf. Its own message can only blame the DEM step; a
// driver that adds other loads (a fluid's) catches this one and names their keys too.
struct DemNotFiniteError : NumericalError {
  using NumericalError::NumericalError;
};
}  // namespace ff
