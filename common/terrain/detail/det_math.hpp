#pragma once
// Elementary functions built from IEEE-754 basic operations only (+, -, *, /, floor, ldexp, fmod), so
// generated terrains do not depend on the platform's libm. Accurate to a few ulp, which is plenty for
// terrain shapes; what matters is that the result is the same everywhere.

namespace marsala::terrain::detail {

/// e^x; 0 below -745, +inf above 709.78.
double det_exp(double x);
/// Sine of an angle in degrees; exact (0, +-1) at multiples of 90 degrees.
double det_sin_deg(double degrees);
/// Cosine of an angle in degrees; exact (0, +-1) at multiples of 90 degrees.
double det_cos_deg(double degrees);

}  // namespace marsala::terrain::detail
